file(REMOVE_RECURSE
  "CMakeFiles/test_force_over_life.dir/unit/test_force_over_life.c.o"
  "CMakeFiles/test_force_over_life.dir/unit/test_force_over_life.c.o.d"
  "test_force_over_life"
  "test_force_over_life.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_force_over_life.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
