"""count_opens.py FILE CMD...: runs CMD and prints how many times FILE was
opened while it ran, as inotify reports it (IN_OPEN), then CMD's exit
status. Each open is followed by its close, so no two events in a row are
the same and the kernel merges none. Exits 2 when FILE cannot be watched."""
import ctypes
import os
import select
import struct
import subprocess
import sys

IN_CLOSE_NOWRITE, IN_OPEN, IN_CLOEXEC = 0x10, 0x20, 0o2000000
libc = ctypes.CDLL(None, use_errno=True)
fd = libc.inotify_init1(IN_CLOEXEC)
if fd < 0 or libc.inotify_add_watch(fd, os.fsencode(sys.argv[1]),
                                    IN_OPEN | IN_CLOSE_NOWRITE) < 0:
    print("count_opens.py: cannot watch %r" % sys.argv[1], file=sys.stderr)
    sys.exit(2)
status = subprocess.run(sys.argv[2:], stdout=subprocess.DEVNULL,
                        stderr=subprocess.DEVNULL).returncode
opens = 0
while select.select([fd], [], [], 0.2)[0]:
    buf = os.read(fd, 65536)
    i = 0
    while i < len(buf):
        _, mask, _, name_len = struct.unpack_from("iIII", buf, i)
        opens += bool(mask & IN_OPEN)
        i += 16 + name_len
print(opens, status)
