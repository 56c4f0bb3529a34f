file(REMOVE_RECURSE
  "CMakeFiles/test_birth_step.dir/unit/test_birth_step.c.o"
  "CMakeFiles/test_birth_step.dir/unit/test_birth_step.c.o.d"
  "test_birth_step"
  "test_birth_step.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_birth_step.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
