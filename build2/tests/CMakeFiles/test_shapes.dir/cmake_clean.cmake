file(REMOVE_RECURSE
  "CMakeFiles/test_shapes.dir/unit/test_shapes.c.o"
  "CMakeFiles/test_shapes.dir/unit/test_shapes.c.o.d"
  "test_shapes"
  "test_shapes.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_shapes.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
