file(REMOVE_RECURSE
  "CMakeFiles/test_sampling.dir/unit/test_sampling.c.o"
  "CMakeFiles/test_sampling.dir/unit/test_sampling.c.o.d"
  "test_sampling"
  "test_sampling.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_sampling.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
