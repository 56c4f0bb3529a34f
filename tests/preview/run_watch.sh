# pfx watch FILE... -o DIR: renders every file, then again on each save;
# the manifest skips the files that did not change; a broken save prints
# its diagnostics and the others go on; SIGTERM stops it with status 0.
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" preview_watch "$@"
cp "$src/tests/preview/dot.yaml" "$work/a.yaml"
sed 's/#ff0000/#ffff00/' "$src/tests/preview/dot.yaml" >"$work/b.yaml"
cd "$work" || exit 2
"$pfx" watch a.yaml b.yaml -o out >watch.out 2>watch.err &
watcher=$!
trap 'kill $watcher 2>/dev/null; rm -rf "$work"' EXIT

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

begin "a save of one file re-renders it and skips the other"
sed -i 's/#ff0000/#0000ff/' a.yaml
rounds 2 || flunk "no second round after the save: $(tail -5 watch.err)"
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
