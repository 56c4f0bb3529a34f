file(REMOVE_RECURSE
  "CMakeFiles/test_render.dir/unit/test_render.c.o"
  "CMakeFiles/test_render.dir/unit/test_render.c.o.d"
  "test_render"
  "test_render.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_render.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
