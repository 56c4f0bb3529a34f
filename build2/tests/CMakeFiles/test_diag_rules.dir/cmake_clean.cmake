file(REMOVE_RECURSE
  "CMakeFiles/test_diag_rules.dir/unit/test_diag_rules.c.o"
  "CMakeFiles/test_diag_rules.dir/unit/test_diag_rules.c.o.d"
  "test_diag_rules"
  "test_diag_rules.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_diag_rules.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
