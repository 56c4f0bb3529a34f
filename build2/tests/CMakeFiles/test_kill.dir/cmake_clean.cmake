file(REMOVE_RECURSE
  "CMakeFiles/test_kill.dir/unit/test_kill.c.o"
  "CMakeFiles/test_kill.dir/unit/test_kill.c.o.d"
  "test_kill"
  "test_kill.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_kill.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
