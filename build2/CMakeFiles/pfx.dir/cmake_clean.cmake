file(REMOVE_RECURSE
  "CMakeFiles/pfx.dir/src/main.c.o"
  "CMakeFiles/pfx.dir/src/main.c.o.d"
  "pfx"
  "pfx.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/pfx.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
