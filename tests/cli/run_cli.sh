#!/usr/bin/env bash
# The command line: exit statuses (0 success, 1 invalid input or I/O failure,
# 2 usage error), where help and errors go, that a failed write leaves
# nothing behind, quiet rendering, that every example validates cleanly and
# renders, and the per-particle footprint that `pfx info` reports. Renders
# are tiny (64x64, frames 0:2; the examples 32x32, one frame) to stay fast.
#
#   bash run_cli.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" cli "$@"
cd "$src" || exit 2
FIRE=effects/fire.yaml
TINY=(--size 64x64 --frames 0:2)

# usage_error NAME MESSAGE ARGS...: exit 2, 'pfx: MESSAGE' and the --help
# hint on stderr, nothing on stdout.
usage_error() {
    begin "$1"
    local msg=$2
    shift 2
    pfx_run "$@"
    want_status 2
    stdout_empty
    stderr_has "pfx: $msg"
    stderr_has "Try 'pfx --help' for more information."
    end
}

# frames_error NAME MESSAGE ARGS...: the same without the --help hint, which
# pfx does not give here: the options parse, but name frames the effect does
# not have (src/main.c reports it after loading the effect).
frames_error() {
    begin "$1"
    local msg=$2
    shift 2
    pfx_run "$@"
    want_status 2
    stdout_empty
    stderr_has "pfx: $msg"
    end
}

# A tiny valid effect of our own, independent of the examples.
cat >"$work/tiny.yaml" <<'EOF'
pfx: 1
duration: 0.2
fps: 10
emitters:
  dot:
    rate: 20
    lifetime: 0.5
EOF
printf 'pfx: 1\nemitters:\n  a:\n    rate: -1\n' >"$work/bad.yaml"

# ---- success: 0
begin "validate a valid file: one summary line on stderr"
pfx_run validate "$FIRE"
want_status 0
[ "$(cat "$work/err")" = "pfx: validated '$FIRE': no warnings" ] || flunk "stderr: $(cat "$work/err")"
stdout_empty
end

begin "validate -q: nothing on stderr"
pfx_run validate -q "$FIRE"
want_status 0
stderr_empty
stdout_empty
end

begin "validate every example"
pfx_run validate effects/*.yaml
want_status 0
n=$(ls effects/*.yaml | wc -l)
[ "$(cat "$work/err")" = "pfx: validated $n files: no warnings" ] || flunk "stderr: $(cat "$work/err")"
end

begin "validate --format json: no summary, every line JSON"
pfx_run validate --format json "$FIRE"
want_status 0
stderr_empty
end

# Every example renders (STYLE.md: effects/ are "each compiled and rendered
# by the tests"; the golden tests render only fire, smoke and fire_loop):
# frame 15 of each, tiny.
for effect in effects/*.yaml; do
    stem=${effect##*/}
    stem=${stem%.yaml}
    begin "render the example $stem"
    pfx_run render "$effect" -o "$work/examples" --size 32x32 --frames 15:15 -q
    want_status 0
    stderr_empty
    png=$work/examples/${stem}_0015.png
    [ -s "$png" ] && [ "$(head -c 4 "$png" | tail -c 3)" = PNG ] || flunk "no PNG ${stem}_0015.png"
    end
done

begin "info"
pfx_run info "$FIRE"
want_status 0
stdout_has "effect $FIRE"
end

begin "render writes the frames"
pfx_run render "$FIRE" -o "$work/frames" "${TINY[@]}" -q
want_status 0
for f in 0000 0001 0002; do
    [ -s "$work/frames/fire_$f.png" ] || flunk "no fire_$f.png"
done
[ -s "$work/frames/fire.manifest.json" ] || flunk "no fire.manifest.json"
n=$(find "$work/frames" -type f | wc -l)
[ "$n" -eq 4 ] || flunk "$n files in the output directory, expected 3 frames and the manifest (no temporaries)"
end

begin "render -q is silent"
pfx_run render "$FIRE" -o "$work/quiet" "${TINY[@]}" -q
want_status 0
stderr_empty
stdout_empty
end

# stderr is a file here, not a terminal: no progress line even without -q.
begin "render without a terminal shows no progress"
pfx_run render "$FIRE" -o "$work/noprogress" "${TINY[@]}"
want_status 0
grep -q 'frame [0-9]* of' "$work/err" && flunk "a progress line on a non-terminal stderr"
grep -q $'\r' "$work/err" && flunk "a carriage return on a non-terminal stderr"
end

# Success is one summary line on stderr unless -q, terminal or not.
begin "render prints a one-line summary"
pfx_run render "$FIRE" -o "$work/summary" "${TINY[@]}"
want_status 0
stdout_empty
[ "$(wc -l <"$work/err")" -eq 1 ] || flunk "stderr has $(wc -l <"$work/err") lines, not 1"
stderr_has "pfx: rendered '$FIRE': 3 frames (0 to 2) in '$work/summary'"
end

begin "bake prints a one-line summary"
pfx_run bake "$FIRE" -o "$work/summary.csv" --frames 0:2
want_status 0
[ "$(wc -l <"$work/err")" -eq 1 ] || flunk "stderr has $(wc -l <"$work/err") lines, not 1"
stderr_has "pfx: baked '$FIRE': frames 0 to 2 as csv to '$work/summary.csv'"
end

# --frames N is one frame, A: runs to the end; --size takes X or x.
begin "--frames 5 renders frame 5 alone"
pfx_run render "$FIRE" -o "$work/one" --frames 5 --size 32x32 -q
want_status 0
[ "$(ls "$work/one" 2>/dev/null | grep -v manifest)" = fire_0005.png ] || flunk "wrote: $(ls "$work/one" 2>/dev/null | tr '\n' ' ')"
end

begin "--frames 117: renders to the last frame"
pfx_run render "$FIRE" -o "$work/tail" --frames 117: --size 32x32 -q
want_status 0
[ "$(ls "$work/tail" 2>/dev/null | grep -v manifest | tr '\n' ' ')" = "fire_0117.png fire_0118.png fire_0119.png " ] ||
    flunk "wrote: $(ls "$work/tail" 2>/dev/null | tr '\n' ' ')"
end

begin "--size 40X24 in capitals"
pfx_run render "$FIRE" -o "$work/caps" --frames 0 --size 40X24 -q
want_status 0
"$py" - "$work/caps/fire_0000.png" <<'PY' || flunk "the PNG is not 40x24"
import struct, sys
with open(sys.argv[1], "rb") as f:
    head = f.read(24)
sys.exit(0 if struct.unpack(">II", head[16:24]) == (40, 24) else 1)
PY
end

begin "bake creates its directory"
pfx_run bake "$FIRE" -o "$work/new/dir/fire.csv" --frames 0:1 -q
want_status 0
[ -s "$work/new/dir/fire.csv" ] || flunk "no $work/new/dir/fire.csv"
end

# On a terminal the progress line appears, and -q removes it. The
# terminal is a pty that Python's pty module opens for pfx's stdout and
# stderr, and exactly what pfx writes there is read back (script(1) once
# gave a run of NUL bytes here under load, in two CI runs of the
# sanitizer tree; it was never reproduced, and it was not pfx's).
on_tty() {
    timeout 60 "$py" -c '
import os, pty, subprocess, sys
m, s = pty.openpty()
p = subprocess.Popen(sys.argv[1:], stdin=subprocess.DEVNULL, stdout=s, stderr=s)
os.close(s)
out = b""
while True:
    try:
        b = os.read(m, 65536)
    except OSError:  # EIO once pfx has closed the terminal
        break
    if not b:
        break
    out += b
sys.stdout.buffer.write(out)
sys.exit(p.wait())
' "$pfx" "$@" </dev/null >"$work/out" 2>"$work/err"
}
begin "render on a terminal shows progress, -q hides it"
on_tty render "$FIRE" -o "$work/tty" "${TINY[@]}"
grep -q 'pfx: frame 2 of 0-2' "$work/out" || flunk "no progress line on a terminal"
on_tty render "$FIRE" -o "$work/tty" "${TINY[@]}" -q
[ -z "$(tr -d '\r\n' <"$work/out")" ] ||
    flunk "output on a terminal with -q: $(head -c 600 "$work/out" | tr -d '\r' | cat -v)"
end

begin "bake writes the CSV"
pfx_run bake "$FIRE" -o "$work/fire.csv" --frames 0:2
want_status 0
[ "$(head -1 "$work/fire.csv" 2>/dev/null)" = "frame,time,emitter,id,x,y,z,vx,vy,vz,age,lifetime,size,r,g,b,a" ] ||
    flunk "the CSV header is wrong"
[ -z "$(find "$work" -maxdepth 1 -name '*fire.csv.*' ! -name fire.csv.manifest.json)" ] ||
    flunk "a temporary file was left behind"
end

begin "bake the tiny effect"
pfx_run bake "$work/tiny.yaml" -o "$work/tiny.csv"
want_status 0
[ -s "$work/tiny.csv" ] || flunk "no CSV"
end

# ---- pfx info: at most 48 bytes per particle for every emitter of fire.yaml
begin "info: bytes per particle <= 48"
pfx_run info "$FIRE"
want_status 0
pools=$(grep -E '^ +pool [0-9]+ particles x [0-9]+ bytes' "$work/out")
[ -n "$pools" ] || flunk "no 'pool N particles x B bytes' line"
emitters=$(sed -n 's/^  emitters \([0-9][0-9]*\)$/\1/p' "$work/out")
[ "$(printf '%s\n' "$pools" | grep -c .)" = "${emitters:-x}" ] ||
    flunk "$(printf '%s\n' "$pools" | grep -c .) pool lines for ${emitters:-?} emitters"
while read -r _ _ _ _ bytes _; do
    [ -n "$bytes" ] || continue
    [ "$bytes" -le 48 ] || flunk "an emitter uses $bytes bytes per particle, more than 48"
done <<<"$pools"
end

# ---- CSS colour names: the exact sRGB value of each name in a frame pixel,
# the known answers from Pillow's table of the CSS names (ImageColor), not
# pfx's: a rebeccapurple background, and an opaque sprite whose gradient
# of names is orange all its life, drawn with a white texture and alpha
# blending.
"$py" -c "from PIL import Image; Image.new('RGBA', (8, 8), (255,) * 4).save('$work/white.png')"
cat >"$work/named.yaml" <<'YAML'
pfx: 1
duration: 0.1
fps: 10
camera: { position: [0, 0, 5], target: [0, 0, 0], ortho: 2 }
image: { size: [64, 64], background: rebeccapurple }
emitters:
  one:
    bursts: [{ time: 0, count: 1 }]
    speed: 0
    lifetime: 10
    size: 1
    color: [orange, orange]
    texture: white.png
    blend: alpha
    forces: []
YAML
begin "CSS colour names render their exact sRGB values"
pfx_run render "$work/named.yaml" -o "$work/named" -q
want_status 0
msg=$("$py" - "$work/named/named_0000.png" <<'PY' 2>&1
import sys
from PIL import Image, ImageColor
im = Image.open(sys.argv[1]).convert("RGBA")
bad = []
for (x, y), name in [((0, 0), "rebeccapurple"), ((63, 63), "rebeccapurple"),
                     ((32, 32), "orange"), ((24, 36), "orange")]:
    want = ImageColor.getrgb(name) + (255,)
    if im.getpixel((x, y)) != want:
        bad.append(f"pixel ({x}, {y}) is {im.getpixel((x, y))}, expected {name} {want}")
print("\n".join(bad))
sys.exit(1 if bad else 0)
PY
) || flunk "$msg"
end

# ---- One texture file named by several emitters is one image: the
# compiler reads it once, the renderer uploads it once, and `pfx info`
# counts it once (8x8 RGBA8: 256 bytes decoded plus 4/3 of that in GL with
# its mipmaps, 597.33 bytes, where one GL copy per emitter made 1280).
# The frames are byte-identical to those of the same effect naming three
# copies of the file (three uploads), and orange at the centre.
cp "$work/white.png" "$work/white2.png"
cp "$work/white.png" "$work/white3.png"
"$py" - "$work/named.yaml" "$work/shared.yaml" "$work/copies.yaml" <<'PY'
import sys
src = open(sys.argv[1]).read()
one = src[src.index("  one:"):]
for out, names in ((sys.argv[2], ["white.png", "./white.png", "white.png"]),
                   (sys.argv[3], ["white.png", "white2.png", "white3.png"])):
    body = "".join(one.replace("  one:", "  e%d:" % i).replace("white.png", n)
                   for i, n in enumerate(names))
    open(out, "w").write(src[:src.index("  one:")] + body)
PY
begin "one texture file named by three emitters is uploaded and counted once"
pfx_run info --format json "$work/shared.yaml"
want_status 0
got=$("$py" -c 'import json,sys; print(json.load(open(sys.argv[1]))["memory"]["parts"]["textures"])' "$work/out")
"$py" -c 'import sys; sys.exit(abs(float(sys.argv[1]) - 256 * (1 + 8 / 3 + 5 / 16)) > 1e-6)' "$got" ||
    flunk "textures: $got bytes, expected 1018.67 (256 decoded + 682.67 in GL as half floats + 80 while its mipmaps are made, once)"
pfx_run render "$work/shared.yaml" -o "$work/shared" -q
want_status 0
pfx_run render "$work/copies.yaml" -o "$work/copies" -q
want_status 0
cmp -s "$work/shared/shared_0000.png" "$work/copies/copies_0000.png" ||
    flunk "the shared texture draws other pixels than three copies"
"$py" -c 'import sys; from PIL import Image, ImageColor
sys.exit(Image.open(sys.argv[1]).convert("RGBA").getpixel((32, 32)) != ImageColor.getrgb("orange") + (255,))' \
    "$work/shared/shared_0000.png" || flunk "the centre is not orange"
end

begin "a misspelt colour name: the nearest name suggested"
printf 'pfx: 1\nemitters:\n  a: { color: [red, oragne] }\n' >"$work/misspelt.yaml"
pfx_run validate "$work/misspelt.yaml"
want_status 1
stderr_has "$work/misspelt.yaml:3:21: error: unknown colour 'oragne' in 'color'; did you mean 'orange'? [PFX3003]"
end

# ---- invalid input or I/O failure: 1
begin "validate an invalid file"
pfx_run validate "$work/bad.yaml"
want_status 1
stderr_has "$work/bad.yaml:4:11: error: 'rate' must be at least 0, got -1"
stdout_empty
! grep -qF "pfx: validated" "$work/err" || flunk "a summary line after a failure"
end

begin "validate a valid and an invalid file"
pfx_run validate "$FIRE" "$work/bad.yaml"
want_status 1
end

begin "validate a missing file"
pfx_run validate nonexistent.yaml
want_status 1
stderr_has "cannot open 'nonexistent.yaml': No such file or directory"
end

begin "render a missing file"
pfx_run render "$work/nonexistent.yaml" -o "$work/missing-out" -q
want_status 1
stderr_has "cannot open '$work/nonexistent.yaml': No such file or directory"
[ ! -e "$work/missing-out" ] || flunk "the output directory was created"
end

begin "render an invalid file creates nothing"
pfx_run render "$work/bad.yaml" -o "$work/bad-out" "${TINY[@]}" -q
want_status 1
[ ! -e "$work/bad-out" ] || flunk "the output directory was created"
end

begin "bake an invalid file creates nothing"
pfx_run bake "$work/bad.yaml" -o "$work/bad.csv"
want_status 1
[ -z "$(find "$work" -maxdepth 1 -name '*bad.csv*')" ] || flunk "a CSV or temporary was created"
end

begin "render under a regular file"
mkdir -p "$work/x" && : >"$work/x/file.txt"
pfx_run render "$FIRE" -o "$work/x/file.txt/out" "${TINY[@]}" -q
want_status 1
stderr_has "cannot create '$work/x/file.txt': Not a directory"
[ -f "$work/x/file.txt" ] && [ ! -s "$work/x/file.txt" ] || flunk "file.txt was changed"
[ "$(find "$work/x" | wc -l)" -eq 2 ] || flunk "something was left in $work/x"
end

begin "render onto a regular file"
pfx_run render "$FIRE" -o "$work/x/file.txt" "${TINY[@]}" -q
want_status 1
stderr_has "'$work/x/file.txt'"
[ "$(find "$work/x" | wc -l)" -eq 2 ] || flunk "something was left in $work/x"
end

begin "bake under a regular file"
pfx_run bake "$FIRE" -o "$work/x/file.txt/a.csv" --frames 0:2
want_status 1
stderr_has "cannot create '$work/x/file.txt': Not a directory"
[ "$(find "$work/x" | wc -l)" -eq 2 ] || flunk "something was left in $work/x"
end

begin "bake onto a directory"
mkdir -p "$work/adir"
pfx_run bake "$FIRE" -o "$work/adir" --frames 0:2
want_status 1
stderr_has "'$work/adir'"
[ -z "$(ls -A "$work/adir")" ] || flunk "something was written into the directory"
[ -z "$(find "$work" -maxdepth 1 -name '*adir.*')" ] || flunk "a temporary was left behind"
end

# ---- renderers: --renderer wins over PFX_RENDERER; one that cannot start
# is one line and exit 1, with nothing written. A hardware EGL device needs
# a kernel driver node, so where there is none egl-gpu must refuse.
begin "--renderer egl-cpu wins over PFX_RENDERER"
PFX_RENDERER=frobnicate pfx_run render "$FIRE" -o "$work/egl-cpu" "${TINY[@]}" -q --renderer egl-cpu
if grep -q "not built into this pfx" "$work/err"; then
    want_status 1
else
    want_status 0
    [ -s "$work/egl-cpu/fire_0002.png" ] || flunk "no fire_0002.png"
fi
end

# one_line_refusal NAME: exit 1, nothing on stdout, one line on stderr that
# starts with "pfx: renderer 'NAME'".
one_line_refusal() {
    want_status 1
    stdout_empty
    [ "$(wc -l <"$work/err")" -eq 1 ] || flunk "stderr has $(wc -l <"$work/err") lines, not 1"
    stderr_has "pfx: renderer '$1'"
}

if ! ls /dev/dri/renderD* /dev/nvidia* >/dev/null 2>&1; then
    begin "--renderer egl-gpu without a GPU is one line, exit 1, nothing written"
    pfx_run render "$FIRE" -o "$work/gpu-out" "${TINY[@]}" --renderer egl-gpu
    one_line_refusal egl-gpu
    [ ! -e "$work/gpu-out" ] || flunk "the output directory was created"
    end

    begin "PFX_RENDERER=egl-gpu without a GPU is one line, exit 1"
    PFX_RENDERER=egl-gpu pfx_run render "$FIRE" -o "$work/gpu-out" "${TINY[@]}"
    one_line_refusal egl-gpu
    [ ! -e "$work/gpu-out" ] || flunk "the output directory was created"
    end

    begin "bench --renderer egl-gpu without a GPU fails before measuring"
    pfx_run bench --renderer egl-gpu
    one_line_refusal egl-gpu
    end
else
    echo "skip: egl-gpu refusals (this machine has a GPU device node)"
fi

# ---- pfx bench emission --json: a row {shape, threads, births_per_s} for
# each of point, sphere and cone, on one thread and on two (this machine's
# cores permitting), each a positive rate
begin "bench emission --json: births per second of point, sphere and cone"
pfx_run bench emission --json
[ "$status" = 0 ] || flunk "exit $status: $(head -c 300 "$work/err")"
"$py" - "$work/out" >"$work/check" 2>&1 <<'EOF' || flunk "$(cat "$work/check")"
import json, os, sys
rep = json.load(open(sys.argv[1]))
rows = rep["emission"]
cores = rep["machine"]["cores"]
want = {(s, t) for s in ("point", "sphere", "cone") for t in ((1, 2) if cores >= 2 else (1,))}
got = {(r["shape"], r["threads"]) for r in rows}
bad = [r for r in rows if not r["births_per_s"] > 0 or set(r) != {"shape", "threads", "births_per_s"}]
if got != want or bad or len(rows) != len(want):
    print("rows %s, want %s, bad %s" % (sorted(got), sorted(want), bad))
    sys.exit(1)
EOF
end

# ---- usage errors: 2
usage_error "no command" "no command given"
usage_error "unknown command" "unknown command 'frobnicate'" frobnicate "$FIRE"
usage_error "unknown option" "unknown option '--bogus'" validate --bogus "$FIRE"
usage_error "unknown short option" "unknown option '-x'" render "$FIRE" -o "$work/u" -x
usage_error "validate without a file" "validate needs at least one FILE" validate
usage_error "render without -o" "render needs -o DIR" render "$FIRE" "${TINY[@]}"
usage_error "bake without -o" "bake needs -o OUT" bake "$FIRE"
usage_error "-o without a value" "option '-o' needs a value" render "$FIRE" -o
usage_error "render with one file twice" "two effects would render into 'fire': rename one" render "$FIRE" "$FIRE" -o "$work/u"
usage_error "--frames 5:2" "--frames takes N, A:B or A: (to the end)" render "$FIRE" -o "$work/u" --frames 5:2
usage_error "--frames x" "--frames takes N, A:B or A:" render "$FIRE" -o "$work/u" --frames x
frames_error "--frames 200: beyond the last frame" "--frames 200: is outside the effect's frames 0:119" \
    render "$FIRE" -o "$work/u" --frames 200:
usage_error "a mistyped command gets a suggestion" "unknown command 'rendr'; did you mean 'render'?" \
    rendr "$FIRE"
usage_error "a mistyped command is named before its options are judged" \
    "unknown command 'rendr'; did you mean 'render'?" rendr "$FIRE" --format exr -o "$work/x"
usage_error "an unknown option in a cluster names itself" "unknown option '-x'" \
    render "$FIRE" -o "$work/u" -x4
usage_error "an unknown long option names itself" "unknown option '--bogus=3'" \
    render "$FIRE" -o "$work/u" --bogus=3
frames_error "--frames beyond the last frame" "--frames 0:1000000 is outside the effect's frames" \
    render "$FIRE" -o "$work/u" --frames 0:1000000 --size 64x64
frames_error "bake --frames beyond the last frame" "--frames 0:1000000 is outside the effect's frames" \
    bake "$FIRE" -o "$work/u.csv" --frames 0:1000000
usage_error "--size 0x10" "--size takes WxH" render "$FIRE" -o "$work/u" --size 0x10
usage_error "--size 64" "--size takes WxH" render "$FIRE" -o "$work/u" --size 64
usage_error "--fps -1" "--fps takes a number" render "$FIRE" -o "$work/u" --fps -1
usage_error "--fps 0" "--fps takes a number" render "$FIRE" -o "$work/u" --fps 0
usage_error "--seed abc" "--seed takes a whole number, got 'abc'" render "$FIRE" -o "$work/u" --seed abc
usage_error "--seed -1" "--seed takes a whole number, got '-1'" render "$FIRE" -o "$work/u" --seed -1
usage_error "--max-particles 0" "--max-particles takes a number" validate --max-particles 0 "$FIRE"
usage_error "--every 0" "--every takes a whole number" bake "$FIRE" -o "$work/u.csv" --every 0
usage_error "--format xml" "--format takes 'text', 'json' or 'sarif', got 'xml'" validate --format xml "$FIRE"
usage_error "unknown benchmark" "unknown benchmark 'frobnicate'" bench frobnicate
usage_error "--renderer frobnicate" \
    "--renderer takes 'auto', 'osmesa', 'egl-cpu' or 'egl-gpu', got 'frobnicate'" \
    render "$FIRE" -o "$work/u" "${TINY[@]}" --renderer frobnicate
usage_error "bench --renderer frobnicate" "--renderer takes" bench --renderer frobnicate
begin "PFX_RENDERER frobnicate"
PFX_RENDERER=frobnicate pfx_run render "$FIRE" -o "$work/u" "${TINY[@]}"
want_status 2
stdout_empty
stderr_has "pfx: PFX_RENDERER takes 'auto', 'osmesa', 'egl-cpu' or 'egl-gpu', got 'frobnicate'"
end
begin "usage errors create nothing"
[ ! -e "$work/u" ] && [ ! -e "$work/u.csv" ] || flunk "a usage error left output behind"
end

# ---- help and version: 0, on stdout
for h in --help -h help; do
    begin "pfx $h"
    pfx_run "$h"
    want_status 0
    stdout_has "usage: pfx validate"
    stderr_empty
    end
done
# A looping effect with no emitters once crashed render and bake
# (SIGFPE: the frame count mod a period of 0 frames, found by fuzz_sim).
printf 'pfx: 1\nloop: true\n' > "$work/empty_loop.yaml"
begin "a looping effect with no emitters renders and bakes"
pfx_run render "$work/empty_loop.yaml" -o "$work/empty_loop" --frames 0:2 -q
finished render && want_status 0
[ -s "$work/empty_loop/empty_loop_0002.png" ] || flunk "no empty_loop_0002.png"
pfx_run bake "$work/empty_loop.yaml" -o "$work/empty_loop.csv" -q
finished bake && want_status 0
pfx_run info "$work/empty_loop.yaml"
stdout_has "(60 frames)"
end
begin "pfx render --help"
pfx_run render --help
want_status 0
stdout_has "usage: pfx render" # its own help only: tests/cli/run_help.sh
end
begin "--version"
pfx_run --version
want_status 0
grep -qE '^pfx [0-9]+\.[0-9]+' "$work/out" || flunk "stdout has no 'pfx X.Y' version"
stderr_empty
end

summary
