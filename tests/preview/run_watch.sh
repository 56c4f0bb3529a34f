# pfx watch FILE... -o DIR: renders every file, then again on each save;
# the manifest skips the files that did not change; a broken save prints
# its diagnostics and the others go on; SIGTERM stops it with status 0.
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" preview_watch "$@"
cp "$src/tests/preview/dot.yaml" "$work/a.yaml"
sed 's/#ff0000/#ffff00/' "$src/tests/preview/dot.yaml" >"$work/b.yaml"
cd "$work" || exit 2
# Every open of a file in $work, one name a line in opens.log (inotify on
# the folder: an open and its close alternate, so the kernel merges none).
"$py" - "$work" >opens.log <<'PY' &
import ctypes, os, struct, sys
libc = ctypes.CDLL(None)
fd = libc.inotify_init1(0)
libc.inotify_add_watch(fd, os.fsencode(sys.argv[1]), 0x20 | 0x10 | 0x08)  # open, closes
open("opens.ready", "w").close()
while True:
    buf = os.read(fd, 65536)
    i = 0
    while i < len(buf):
        _, mask, _, n = struct.unpack_from("iIII", buf, i)
        if mask & 0x20:
            print(buf[i + 16:i + 16 + n].rstrip(b"\0").decode(errors="replace"), flush=True)
        i += 16 + n
PY
logger=$!
for _ in $(seq 100); do [ -e opens.ready ] && break; sleep 0.1; done
"$pfx" watch a.yaml b.yaml -o out >watch.out 2>watch.err &
watcher=$!
trap 'kill $watcher $logger 2>/dev/null; rm -rf "$work"' EXIT

# rounds N: waits (at most 60 s) until the watcher has finished N renders.
rounds() {
    for _ in $(seq 600); do
        [ "$(grep -c '^pfx: watching 2 files' watch.err)" -ge "$1" ] && return 0
        sleep 0.1
    done
    return 1
}
# centre FILE: the middle pixel of a frame, as "R G B A".
centre() { "$py" -c 'import sys; from PIL import Image
print(*Image.open(sys.argv[1]).convert("RGBA").getpixel((48, 48)))' "$1"; }

begin "the first round renders both files"
rounds 1 || flunk "no round after 60 s: $(cat watch.err)"
[ -f out/a/a_0009.png ] && [ -f out/b/b_0009.png ] || flunk "frames missing: $(ls -R out)"
[ "$(centre out/a/a_0005.png)" = "254 0 0 255" ] || flunk "a's middle is $(centre out/a/a_0005.png)"
end
# An old time on one of b's frames: a render that rewrote it would show.
touch -d '2000-01-01' out/b/b_0005.png
b_before=$(stat -c %Y out/b/b_0005.png)

begin "each file is read once a round (the render's load names what to watch)"
[ -e opens.ready ] || flunk "the inotify logger did not start"
[ "$(grep -cx a.yaml opens.log) $(grep -cx b.yaml opens.log)" = "1 1" ] ||
    flunk "opens of a.yaml and b.yaml in the first round: $(grep -cx a.yaml opens.log) $(grep -cx b.yaml opens.log)"
end

begin "a save of one file re-renders it and skips the other"
# The save as an editor makes it, a new file renamed over the old, which
# reads nothing: every open of a.yaml from here is pfx's.
opened=$(grep -cx a.yaml opens.log)
sed 's/#ff0000/#0000ff/' "$src/tests/preview/dot.yaml" >a.yaml.new && mv a.yaml.new a.yaml
rounds 2 || flunk "no second round after the save: $(tail -5 watch.err)"
sleep 0.2
[ $(($(grep -cx a.yaml opens.log) - opened)) = 1 ] ||
    flunk "a.yaml opened $(($(grep -cx a.yaml opens.log) - opened)) times for one save, want 1"
[ "$(centre out/a/a_0005.png)" = "0 0 254 255" ] || flunk "a's middle is $(centre out/a/a_0005.png)"
[ "$(stat -c %Y out/b/b_0005.png)" = "$b_before" ] || flunk "b's frames were written again"
grep -q "^pfx: 'b.yaml' is up to date in 'out/b'" watch.err || flunk "b not said up to date"
end

begin "a broken save prints its diagnostic; the other file is still checked"
sed -i 's/size: 1.2/size: 1.2./' a.yaml
rounds 3 || flunk "no third round after the typo"
line=$(grep -n 'size: 1.2\.' a.yaml | cut -d: -f1)
grep -q "^a.yaml:$line:11: error: " watch.err || flunk "no diagnostic at a.yaml:$line:11: $(tail -8 watch.err)"
[ "$(tail -n 50 watch.err | grep -c "'b.yaml' is up to date")" -ge 2 ] || flunk "b skipped less than twice"
end

begin "SIGTERM stops it between renders with status 0"
kill -TERM $watcher
wait $watcher
status=$?
[ "$status" -eq 0 ] || flunk "exit status $status"
end
summary
