#!/usr/bin/env bash
# The command line: exit statuses (0 success, 1 invalid input or I/O failure,
# 2 usage error), where help and errors go, that a failed write leaves
# nothing behind, quiet rendering, and the per-particle footprint that
# `pfx info` reports. Renders are tiny (64x64, frames 0:2) to stay fast.
#
#   bash run_cli.sh PATH-TO-PFX SOURCE-DIR
set -u
if [ $# -ne 2 ]; then
    echo "usage: bash run_cli.sh PATH-TO-PFX SOURCE-DIR" >&2
    exit 2
fi
PFX=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
cd "$2" || exit 2
TMP=$(mktemp -d "${TMPDIR:-/tmp}/pfx-cli.XXXXXX") || exit 2
trap 'rm -rf "$TMP"' EXIT
FIRE=effects/fire.yaml
TINY=(--size 64x64 --frames 0:2)

passed=0
failed=0
case_ok=1
check_name=
fail() {
    case_ok=0
    echo "FAIL $check_name: $1"
}
# begin NAME ... end: one named check; it counts once however many of its
# assertions fail.
begin() {
    check_name=$1
    case_ok=1
}
end() {
    if [ "$case_ok" = 1 ]; then
        passed=$((passed + 1))
    else
        failed=$((failed + 1))
        echo "  stdout: $(head -c 400 "$TMP/out" | cat -v)"
        echo "  stderr: $(head -c 400 "$TMP/err" | cat -v)"
    fi
}

# run ARGS...: pfx with a time bound; stdout, stderr and status captured.
run() {
    timeout 60 "$PFX" "$@" >"$TMP/out" 2>"$TMP/err"
    status=$?
}
want_status() {
    [ "$status" -eq "$1" ] || fail "exit status $status, expected $1"
}
stderr_has() {
    grep -qF -- "$1" "$TMP/err" || fail "stderr lacks '$1'"
}
stdout_has() {
    grep -qF -- "$1" "$TMP/out" || fail "stdout lacks '$1'"
}
stdout_empty() {
    [ ! -s "$TMP/out" ] || fail "stdout is not empty"
}
stderr_empty() {
    [ ! -s "$TMP/err" ] || fail "stderr is not empty"
}

# usage_error NAME MESSAGE ARGS...: exit 2, 'pfx: MESSAGE' and the --help
# hint on stderr, nothing on stdout.
usage_error() {
    begin "$1"
    local msg=$2
    shift 2
    run "$@"
    want_status 2
    stdout_empty
    stderr_has "pfx: $msg"
    end
}

# A tiny valid effect of our own, independent of the examples.
cat >"$TMP/tiny.yaml" <<'EOF'
pfx: 1
duration: 0.2
fps: 10
emitters:
  dot:
    rate: 20
    lifetime: 0.5
EOF
printf 'pfx: 1\nemitters:\n  a:\n    rate: -1\n' >"$TMP/bad.yaml"

# ---- success: 0
begin "validate a valid file"
run validate "$FIRE"
want_status 0
stderr_empty
stdout_empty
end

begin "validate every example"
run validate effects/*.yaml
want_status 0
end

begin "info"
run info "$FIRE"
want_status 0
stdout_has "effect $FIRE"
end

begin "render writes the frames"
run render "$FIRE" -o "$TMP/frames" "${TINY[@]}" -q
want_status 0
for f in 0000 0001 0002; do
    [ -s "$TMP/frames/fire_$f.png" ] || fail "no fire_$f.png"
done
n=$(find "$TMP/frames" -type f | wc -l)
[ "$n" -eq 3 ] || fail "$n files in the output directory, expected 3 (no temporaries)"
end

begin "render -q is silent"
run render "$FIRE" -o "$TMP/quiet" "${TINY[@]}" -q
want_status 0
stderr_empty
stdout_empty
end

# stderr is a file here, not a terminal: no progress line even without -q.
begin "render without a terminal shows no progress"
run render "$FIRE" -o "$TMP/noprogress" "${TINY[@]}"
want_status 0
grep -q 'frame' "$TMP/err" && fail "a progress line on a non-terminal stderr"
grep -q $'\r' "$TMP/err" && fail "a carriage return on a non-terminal stderr"
end

# On a terminal (a pty from script(1), when installed) the progress line
# appears, and -q removes it.
if command -v script >/dev/null 2>&1; then
    begin "render on a terminal shows progress, -q hides it"
    q() { printf "'%s' " "$@"; }
    timeout 60 script -qec "$(q "$PFX" render "$FIRE" -o "$TMP/tty" "${TINY[@]}") 2>&1" /dev/null \
        </dev/null >"$TMP/out" 2>"$TMP/err"
    grep -q 'pfx: frame 2 of 0-2' "$TMP/out" || fail "no progress line on a terminal"
    timeout 60 script -qec "$(q "$PFX" render "$FIRE" -o "$TMP/tty" "${TINY[@]}" -q) 2>&1" /dev/null \
        </dev/null >"$TMP/out" 2>"$TMP/err"
    [ -z "$(tr -d '\r\n' <"$TMP/out")" ] || fail "output on a terminal with -q"
    end
fi

begin "bake writes the CSV"
run bake "$FIRE" -o "$TMP/fire.csv" --frames 0:2
want_status 0
[ "$(head -1 "$TMP/fire.csv" 2>/dev/null)" = "frame,time,emitter,id,x,y,z,vx,vy,vz,age,lifetime,size,r,g,b,a" ] ||
    fail "the CSV header is wrong"
[ -z "$(find "$TMP" -maxdepth 1 -name 'fire.csv.*')" ] || fail "a temporary file was left behind"
end

begin "bake the tiny effect"
run bake "$TMP/tiny.yaml" -o "$TMP/tiny.csv"
want_status 0
[ -s "$TMP/tiny.csv" ] || fail "no CSV"
end

# ---- pfx info: at most 48 bytes per particle for every emitter of fire.yaml
begin "info: bytes per particle <= 48"
run info "$FIRE"
want_status 0
pools=$(grep -E '^ +pool [0-9]+ particles x [0-9]+ bytes' "$TMP/out")
[ -n "$pools" ] || fail "no 'pool N particles x B bytes' line"
emitters=$(sed -n 's/^  emitters \([0-9][0-9]*\)$/\1/p' "$TMP/out")
[ "$(printf '%s\n' "$pools" | grep -c .)" = "${emitters:-x}" ] ||
    fail "$(printf '%s\n' "$pools" | grep -c .) pool lines for ${emitters:-?} emitters"
while read -r _ _ _ _ bytes _; do
    [ -n "$bytes" ] || continue
    [ "$bytes" -le 48 ] || fail "an emitter uses $bytes bytes per particle, more than 48"
done <<<"$pools"
end

# ---- invalid input or I/O failure: 1
begin "validate an invalid file"
run validate "$TMP/bad.yaml"
want_status 1
stderr_has "$TMP/bad.yaml:4:11: error: 'rate' must be at least 0, got -1"
stdout_empty
end

begin "validate a valid and an invalid file"
run validate "$FIRE" "$TMP/bad.yaml"
want_status 1
end

begin "validate a missing file"
run validate nonexistent.yaml
want_status 1
stderr_has "cannot open 'nonexistent.yaml': No such file or directory"
end

begin "render a missing file"
run render "$TMP/nonexistent.yaml" -o "$TMP/missing-out" -q
want_status 1
stderr_has "cannot open '$TMP/nonexistent.yaml': No such file or directory"
[ ! -e "$TMP/missing-out" ] || fail "the output directory was created"
end

begin "render an invalid file creates nothing"
run render "$TMP/bad.yaml" -o "$TMP/bad-out" "${TINY[@]}" -q
want_status 1
[ ! -e "$TMP/bad-out" ] || fail "the output directory was created"
end

begin "bake an invalid file creates nothing"
run bake "$TMP/bad.yaml" -o "$TMP/bad.csv"
want_status 1
[ -z "$(find "$TMP" -maxdepth 1 -name 'bad.csv*')" ] || fail "a CSV or temporary was created"
end

begin "render under a regular file"
mkdir -p "$TMP/x" && : >"$TMP/x/file.txt"
run render "$FIRE" -o "$TMP/x/file.txt/out" "${TINY[@]}" -q
want_status 1
stderr_has "cannot create '$TMP/x/file.txt': Not a directory"
[ -f "$TMP/x/file.txt" ] && [ ! -s "$TMP/x/file.txt" ] || fail "file.txt was changed"
[ "$(find "$TMP/x" | wc -l)" -eq 2 ] || fail "something was left in $TMP/x"
end

begin "render onto a regular file"
run render "$FIRE" -o "$TMP/x/file.txt" "${TINY[@]}" -q
want_status 1
stderr_has "'$TMP/x/file.txt'"
[ "$(find "$TMP/x" | wc -l)" -eq 2 ] || fail "something was left in $TMP/x"
end

begin "bake into a missing directory"
run bake "$FIRE" -o /nonexistent/dir/a.csv --frames 0:2
want_status 1
stderr_has "cannot write '/nonexistent/dir/a.csv': No such file or directory"
[ ! -e /nonexistent ] || fail "/nonexistent was created"
end

begin "bake onto a directory"
mkdir -p "$TMP/adir"
run bake "$FIRE" -o "$TMP/adir" --frames 0:2
want_status 1
stderr_has "'$TMP/adir'"
[ -z "$(ls -A "$TMP/adir")" ] || fail "something was written into the directory"
[ -z "$(find "$TMP" -maxdepth 1 -name 'adir.*')" ] || fail "a temporary was left behind"
end

# ---- renderers: --renderer wins over PFX_RENDERER; one that cannot start
# is one line and exit 1, with nothing written. A hardware EGL device needs
# a kernel driver node, so where there is none egl-gpu must refuse.
begin "--renderer egl-cpu wins over PFX_RENDERER"
PFX_RENDERER=frobnicate run render "$FIRE" -o "$TMP/egl-cpu" "${TINY[@]}" -q --renderer egl-cpu
if grep -q "not built into this pfx" "$TMP/err"; then
    want_status 1
else
    want_status 0
    [ -s "$TMP/egl-cpu/fire_0002.png" ] || fail "no fire_0002.png"
fi
end

# one_line_refusal NAME: exit 1, nothing on stdout, one line on stderr that
# starts with "pfx: renderer 'NAME'".
one_line_refusal() {
    want_status 1
    stdout_empty
    [ "$(wc -l <"$TMP/err")" -eq 1 ] || fail "stderr has $(wc -l <"$TMP/err") lines, not 1"
    stderr_has "pfx: renderer '$1'"
}

if ! ls /dev/dri/renderD* /dev/nvidia* >/dev/null 2>&1; then
    begin "--renderer egl-gpu without a GPU is one line, exit 1, nothing written"
    run render "$FIRE" -o "$TMP/gpu-out" "${TINY[@]}" --renderer egl-gpu
    one_line_refusal egl-gpu
    [ ! -e "$TMP/gpu-out" ] || fail "the output directory was created"
    end

    begin "PFX_RENDERER=egl-gpu without a GPU is one line, exit 1"
    PFX_RENDERER=egl-gpu run render "$FIRE" -o "$TMP/gpu-out" "${TINY[@]}"
    one_line_refusal egl-gpu
    [ ! -e "$TMP/gpu-out" ] || fail "the output directory was created"
    end

    begin "bench --renderer egl-gpu without a GPU fails before measuring"
    run bench --renderer egl-gpu
    one_line_refusal egl-gpu
    end
else
    echo "skip: egl-gpu refusals (this machine has a GPU device node)"
fi

# ---- usage errors: 2
usage_error "no command" "no command given"
usage_error "unknown command" "unknown command 'frobnicate'" frobnicate "$FIRE"
usage_error "unknown option" "unknown option '--bogus'" validate --bogus "$FIRE"
usage_error "unknown short option" "unknown option '-x'" render "$FIRE" -o "$TMP/u" -x
usage_error "validate without a file" "validate needs at least one FILE" validate
usage_error "render without -o" "render needs -o DIR" render "$FIRE" "${TINY[@]}"
usage_error "bake without -o" "bake needs -o OUT.csv" bake "$FIRE"
usage_error "-o without a value" "option '-o' needs a value" render "$FIRE" -o
usage_error "render with two files" "render takes one FILE" render "$FIRE" "$FIRE" -o "$TMP/u"
usage_error "--frames 5:2" "--frames takes A:B with 0 <= A <= B <= 100000000, got '5:2'" \
    render "$FIRE" -o "$TMP/u" --frames 5:2
usage_error "--frames without a colon" "--frames takes A:B" render "$FIRE" -o "$TMP/u" --frames 5
usage_error "--frames beyond the last frame" "--frames 0:1000000 is outside the effect's frames" \
    render "$FIRE" -o "$TMP/u" --frames 0:1000000 --size 64x64
usage_error "bake --frames beyond the last frame" "--frames 0:1000000 is outside the effect's frames" \
    bake "$FIRE" -o "$TMP/u.csv" --frames 0:1000000
usage_error "--size 0x10" "--size takes WxH" render "$FIRE" -o "$TMP/u" --size 0x10
usage_error "--size 64" "--size takes WxH" render "$FIRE" -o "$TMP/u" --size 64
usage_error "--fps -1" "--fps takes a number" render "$FIRE" -o "$TMP/u" --fps -1
usage_error "--fps 0" "--fps takes a number" render "$FIRE" -o "$TMP/u" --fps 0
usage_error "--seed abc" "--seed takes a whole number, got 'abc'" render "$FIRE" -o "$TMP/u" --seed abc
usage_error "--seed -1" "--seed takes a whole number, got '-1'" render "$FIRE" -o "$TMP/u" --seed -1
usage_error "--max-particles 0" "--max-particles takes a number" validate --max-particles 0 "$FIRE"
usage_error "--every 0" "--every takes a whole number" bake "$FIRE" -o "$TMP/u.csv" --every 0
usage_error "--format xml" "--format takes 'text' or 'json', got 'xml'" validate --format xml "$FIRE"
usage_error "unknown benchmark" "unknown benchmark 'frobnicate'" bench frobnicate
usage_error "--renderer frobnicate" \
    "--renderer takes 'auto', 'osmesa', 'egl-cpu' or 'egl-gpu', got 'frobnicate'" \
    render "$FIRE" -o "$TMP/u" "${TINY[@]}" --renderer frobnicate
usage_error "bench --renderer frobnicate" "--renderer takes" bench --renderer frobnicate
begin "PFX_RENDERER frobnicate"
PFX_RENDERER=frobnicate run render "$FIRE" -o "$TMP/u" "${TINY[@]}"
want_status 2
stdout_empty
stderr_has "pfx: PFX_RENDERER takes 'auto', 'osmesa', 'egl-cpu' or 'egl-gpu', got 'frobnicate'"
end
begin "usage errors create nothing"
[ ! -e "$TMP/u" ] && [ ! -e "$TMP/u.csv" ] || fail "a usage error left output behind"
end

# ---- help and version: 0, on stdout
for h in --help -h help; do
    begin "pfx $h"
    run "$h"
    want_status 0
    stdout_has "usage: pfx validate"
    stderr_empty
    end
done
begin "pfx render --help"
run render --help
want_status 0
stdout_has "usage: pfx validate"
end
begin "--version"
run --version
want_status 0
grep -qE '^pfx [0-9]+\.[0-9]+' "$TMP/out" || fail "stdout has no 'pfx X.Y' version"
stderr_empty
end

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
