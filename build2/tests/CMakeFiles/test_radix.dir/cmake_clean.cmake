file(REMOVE_RECURSE
  "CMakeFiles/test_radix.dir/unit/test_radix.c.o"
  "CMakeFiles/test_radix.dir/unit/test_radix.c.o.d"
  "test_radix"
  "test_radix.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_radix.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
