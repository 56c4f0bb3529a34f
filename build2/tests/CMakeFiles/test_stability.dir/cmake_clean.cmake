file(REMOVE_RECURSE
  "CMakeFiles/test_stability.dir/unit/test_stability.c.o"
  "CMakeFiles/test_stability.dir/unit/test_stability.c.o.d"
  "test_stability"
  "test_stability.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_stability.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
