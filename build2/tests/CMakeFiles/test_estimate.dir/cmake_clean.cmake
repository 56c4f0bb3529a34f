file(REMOVE_RECURSE
  "CMakeFiles/test_estimate.dir/unit/test_estimate.c.o"
  "CMakeFiles/test_estimate.dir/unit/test_estimate.c.o.d"
  "test_estimate"
  "test_estimate.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_estimate.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
