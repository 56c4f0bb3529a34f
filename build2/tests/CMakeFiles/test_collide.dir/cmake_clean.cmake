file(REMOVE_RECURSE
  "CMakeFiles/test_collide.dir/unit/test_collide.c.o"
  "CMakeFiles/test_collide.dir/unit/test_collide.c.o.d"
  "test_collide"
  "test_collide.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_collide.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
