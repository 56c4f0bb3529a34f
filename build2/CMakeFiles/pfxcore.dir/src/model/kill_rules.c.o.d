CMakeFiles/pfxcore.dir/src/model/kill_rules.c.o: \
 /work/main/src/model/kill_rules.c /usr/include/stdc-predef.h \
 /work/main/src/model/kill_rules.h \
 /usr/lib/gcc/x86_64-linux-gnu/12/include/stdbool.h \
 /usr/lib/gcc/x86_64-linux-gnu/12/include/stddef.h \
 /work/main/src/model/kinds.h
