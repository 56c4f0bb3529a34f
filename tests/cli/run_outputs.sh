#!/usr/bin/env bash
# Output files under stress: interrupted by a signal, past `ulimit -f`, on
# a full disk, with names at the file system's length limit, under a
# symlink loop. Each must end in one clean message naming the path and the
# errno (or die of the signal it got), and leave nothing half-written: no
# partial file and no temporary.
#
#   bash run_outputs.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" outputs "$@"
cd "$src" || exit 2
FIRE=effects/fire.yaml

# leftovers DIR: flunks when DIR holds anything (a frame, a CSV or a
# temporary), listing it.
leftovers() {
    local left
    left=$(ls -A "$1" 2>/dev/null)
    [ -z "$left" ] || flunk "left in $1: $(echo $left | head -c 200)"
}

# A bake slow enough to interrupt: 100,000 particles a frame for 20 s.
cat >"$work/heavy.yaml" <<'EOF2'
pfx: 1
duration: 20
emitters:
  dust:
    rate: 100000
    lifetime: 1
    speed: [0, 1]
    spread: 180
EOF2

# ---- signals: the temporary goes, the process dies of the signal
# interrupt NAME SIGNAL DIR ARGS...: starts pfx ARGS (SIGINT not ignored,
# as from a terminal), waits until a temporary file appears in DIR (at most
# 60 s), sends SIGNAL, and expects pfx to end within 10 s with the shell's
# status 128 + the signal's number and DIR to hold no temporary.
interrupt() {
    local name=$1 sig=$2 dir=$3
    shift 3
    begin "$name"
    local got
    got=$("$py" - "$pfx" "$sig" "$dir" "$@" <<'EOF2'
import os, signal, subprocess, sys, time
pfx, sig, d, args = sys.argv[1], getattr(signal, "SIG" + sys.argv[2]), sys.argv[3], sys.argv[4:]
p = subprocess.Popen([pfx] + args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                     preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
end = time.time() + 60
while time.time() < end and p.poll() is None:
    if os.path.isdir(d) and any(".tmp-" in f for f in os.listdir(d)):
        break
    time.sleep(0.01)
else:
    p.kill()
    print("no temporary appeared in %s" % d)
    sys.exit()
p.send_signal(sig)
try:
    rc = p.wait(10)
except subprocess.TimeoutExpired:
    p.kill()
    print("still running 10 s after the signal")
    sys.exit()
print("status %d" % (128 - rc if rc < 0 else rc))
EOF2
)
    local want="status $((128 + $(kill -l "$sig")))"
    [ "$got" = "$want" ] || flunk "$got, expected $want"
    ls -A "$dir" | grep -q '\.tmp-' && flunk "a temporary is left in $dir: $(ls -A "$dir" | grep '\.tmp-')"
    end
}

interrupt "SIGINT during render: status 130, no temporary" INT "$work/sigint" \
    render "$FIRE" -o "$work/sigint" --size 4096x4096 -q
interrupt "SIGTERM during render: status 143, no temporary" TERM "$work/sigterm" \
    render "$FIRE" -o "$work/sigterm" --size 4096x4096 -q
mkdir -p "$work/sigbake"
interrupt "SIGTERM during bake: status 143, no partial CSV" TERM "$work/sigbake" \
    bake "$work/heavy.yaml" -o "$work/sigbake/heavy.csv"
[ ! -e "$work/sigbake/heavy.csv" ] || fail "SIGTERM during bake left heavy.csv"
interrupt "SIGINT during bake: status 130, no partial CSV" INT "$work/sigbake" \
    bake "$work/heavy.yaml" -o "$work/sigbake/heavy.csv"

# ---- ulimit -f: SIGXFSZ is ignored, the write fails with EFBIG
begin "bake past ulimit -f: the path and 'File too large', nothing left"
mkdir -p "$work/fsize"
(
    ulimit -f 10
    pfx_run bake "$FIRE" -o "$work/fsize/fire.csv"
    echo "$status" >"$work/fsize.status"
)
status=$(cat "$work/fsize.status")
finished && want_status 1
stderr_has "pfx: cannot write '$work/fsize/fire.csv': File too large"
leftovers "$work/fsize"
end

begin "render past ulimit -f: the path and 'File too large', nothing left"
mkdir -p "$work/fsize_png"
(
    ulimit -f 10
    pfx_run render "$FIRE" -o "$work/fsize_png" --frames 30:32 -q
    echo "$status" >"$work/fsize.status"
)
status=$(cat "$work/fsize.status")
finished && want_status 1
stderr_has "pfx: cannot write '$work/fsize_png/fire_0030.png': File too large"
leftovers "$work/fsize_png"
end

# ---- a full disk: a 64 KiB tmpfs in a private mount namespace, where
# unprivileged user namespaces (or root) allow one.
full=$work/full
mkdir -p "$full"
if unshare -rm sh -c "mount -t tmpfs -o size=64k tmpfs '$full'" 2>/dev/null; then
    for what in bake render; do
        begin "$what into a full disk: the path and 'No space left on device', nothing left"
        if [ "$what" = bake ]; then
            args=(bake "$FIRE" -o "$full/fire.csv")
            target=$full/fire.csv
        else
            args=(render "$FIRE" -o "$full" --frames 30:40 -q)
            target=$full/fire_00
        fi
        unshare -rm sh -c 'd=$1 && mount -t tmpfs -o size=64k tmpfs "$d" || exit 99
            shift; "$@" >"$0.out" 2>"$0.err"; echo $? >"$0.status"; ls -A "$d" >"$0.left"' \
            "$work/full" "$full" "$pfx" "${args[@]}"
        status=$(cat "$work/full.status")
        cp "$work/full.err" "$work/err"
        want_status 1
        stderr_has "pfx: cannot write '$target"
        stderr_has "': No space left on device"
        grep -q '\.tmp-' "$work/full.left" && flunk "a temporary is left: $(cat "$work/full.left")"
        [ "$what" = render ] || [ ! -s "$work/full.left" ] || flunk "left: $(cat "$work/full.left")"
        end
    done
else
    echo "skip: full-disk checks (no tmpfs in a user namespace here)"
fi

# ---- names at the limit: the temporary fits whenever the final name does.
# A render also writes <stem>.manifest.json, 5 bytes longer than a frame's
# name, so the stems are those whose manifest fits; the temporaries of both
# the frame and the manifest have to be cut.
name_max=$(getconf NAME_MAX "$work" 2>/dev/null || echo 255)
for stem_len in 236 239 $((name_max - 14)); do
    stem=$(printf 'e%.0s' $(seq "$stem_len"))
    cp "$work/heavy.yaml" "$work/$stem.yaml"
    begin "render an effect whose name is $stem_len bytes: ${stem_len}+9-byte frames"
    pfx_run render "$work/$stem.yaml" -o "$work/long$stem_len" --size 16x16 --frames 0:0 -q
    finished && want_status 0
    stderr_empty
    [ -s "$work/long$stem_len/${stem}_0000.png" ] || flunk "no ${stem}_0000.png"
    [ -s "$work/long$stem_len/$stem.manifest.json" ] || flunk "no $stem.manifest.json"
    [ "$(ls -A "$work/long$stem_len" | wc -l)" -eq 2 ] ||
        flunk "more than the frame and the manifest were left"
    end
    rm -f "$work/$stem.yaml"
done
stem=$(printf 'e%.0s' $(seq $((name_max - 8))))
cp "$work/heavy.yaml" "$work/$stem.yaml"
begin "a frame name past NAME_MAX: 'File name too long' for that name, nothing left"
pfx_run render "$work/$stem.yaml" -o "$work/toolong" --size 16x16 --frames 0:0 -q
finished && want_status 1
stderr_has "pfx: cannot write '$work/toolong/${stem}_0000.png': File name too long"
leftovers "$work/toolong"
end
rm -f "$work/$stem.yaml"

# ---- an output name taken by a directory: refused before any work (the
# atlas JSON is written last, so finding it then cost the whole render
# and the previous atlas image), nothing written
for what in fire_0002.png fire_atlas.json; do
    begin "render with a directory at $what: refused before the first frame"
    rm -rf "$work/dirs" && mkdir -p "$work/dirs/$what"
    pfx_run render "$FIRE" -o "$work/dirs" --size 16x16 --frames 0:3 --atlas -q
    finished && want_status 1
    stderr_has "pfx: cannot write '$work/dirs/$what': Is a directory"
    [ "$(cd "$work/dirs" && ls -A)" = "$what" ] || flunk "wrote $(cd "$work/dirs" && ls -A | tr '\n' ' ')"
    end
done
begin "bake -o a directory: refused before any work"
rm -rf "$work/dirs" && mkdir -p "$work/dirs/c.csv"
pfx_run bake "$FIRE" -o "$work/dirs/c.csv" --frames 0:3
finished && want_status 1
stderr_has "pfx: cannot write '$work/dirs/c.csv': Is a directory"
[ "$(cd "$work/dirs" && ls -A)" = "c.csv" ] || flunk "wrote $(cd "$work/dirs" && ls -A | tr '\n' ' ')"
end

# ---- an output directory that is a symlink loop: the real errno
ln -s loop "$work/loop"
begin "render under a symlink loop: 'Too many levels of symbolic links'"
pfx_run render "$FIRE" -o "$work/loop/out" --size 16x16 --frames 0:0 -q
finished && want_status 1
stderr_has "pfx: cannot create '$work/loop': Too many levels of symbolic links"
end
begin "bake under a symlink loop: the path and the errno"
pfx_run bake "$FIRE" -o "$work/loop/a.csv" --frames 0:0
finished && want_status 1
# bake creates the directory of OUT, as render creates DIR.
stderr_has "pfx: cannot create '$work/loop': Too many levels of symbolic links"
end

summary
