file(REMOVE_RECURSE
  "CMakeFiles/test_emission.dir/unit/test_emission.c.o"
  "CMakeFiles/test_emission.dir/unit/test_emission.c.o.d"
  "test_emission"
  "test_emission.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_emission.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
