#!/usr/bin/env bash
# Diagnostics as data. Every tests/diag/NAME.yaml is a broken effect;
# NAME.expected holds the exact stderr of `pfx validate tests/diag/NAME.yaml`
# run from the source root, and NAME.status the exit status when it is not 1.
# Each case also runs with --format json, whose every line must be a JSON
# object naming the same diagnostics as the text (check_json.py). Hostile
# files too large or too binary to commit are generated into a temporary
# directory and checked by pattern. Every run is bounded: 10 s, and 1 GB of
# address space unless the binary is built with AddressSanitizer (whose
# shadow memory needs more); a signal or a timeout is a failure.
#
# CTest runs one case per test (tests/CMakeLists.txt): diag/NAME for each
# committed case, diag/generated/NAME for each gen_NAME function below, and
# diag/stray for the files that belong to no case.
#
#   bash diag.sh PFX SOURCE-DIR case [NAME...]       committed cases (all
#                                                    without a NAME)
#   bash diag.sh PFX SOURCE-DIR generated [NAME...]  generated cases
#   bash diag.sh PFX SOURCE-DIR stray                no file without a case
#   PFX_DIAG_UPDATE=1 bash diag.sh PFX DIR case [NAME...]  rewrite
#       NAME.expected and NAME.status from the actual output (read the diff
#       before committing); `PFX_DIAG_UPDATE=1 ctest -R diag/NAME` does the
#       same through CTest.
#
# A case with a NAME.bug file is pinned to what pfx SHOULD print: the .bug
# says what is wrong. It fails until the bug is fixed, and the update mode
# leaves it alone; delete the .bug when the fix lands.
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" diag "$@"
cd "$src" || exit 2
mode=${3-}
shift 3 2>/dev/null || shift $#
UPDATE=${PFX_DIAG_UPDATE:-0}

# Whether pfx has AddressSanitizer: CTest says so in PFX_ASAN (0 or 1), which
# saves reading the binary once per case; by hand, the binary is searched.
pfx_timeout=10
pfx_vm=1000000 # KiB
asan=${PFX_ASAN-}
if [ -z "$asan" ]; then
    asan=0
    grep -q __asan_init "$pfx" 2>/dev/null && asan=1
fi
if [ "$asan" = 1 ]; then
    pfx_vm=unlimited
    echo "note: $pfx uses AddressSanitizer: no ulimit -v"
fi

# json_form FILE STATUS: `pfx validate --format json FILE` exits STATUS,
# writes nothing to stdout, and its lines are the diagnostics of the text
# run, whose stderr the caller left in $work/text.err.
json_form() {
    local msg
    pfx_run validate --format json "$1"
    finished "--format json" || return
    [ "$status" -eq "$2" ] || flunk "--format json exit status $status, expected $2"
    [ ! -s "$work/out" ] || flunk "--format json wrote to stdout"
    msg=$("$py" "$src/tests/diag/check_json.py" "$work/text.err" "$work/err" "$1" 2>&1) ||
        flunk "--format json: $msg"
}

# ---- committed cases: exact stderr

# committed_case NAME: the exact stderr and status, then the JSON form.
committed_case() {
    local name=$1 yaml=tests/diag/$1.yaml expected=tests/diag/$1.expected want=1
    begin "$name"
    if [ ! -f "$yaml" ]; then
        flunk "no $yaml"
        end
        return
    fi
    [ -f "tests/diag/$name.status" ] && want=$(cat "tests/diag/$name.status")
    pfx_run validate "$yaml"
    if finished; then
        if [ "$UPDATE" = 1 ] && [ ! -f "tests/diag/$name.bug" ]; then
            cp "$work/err" "$expected"
            if [ "$status" -eq 1 ]; then
                rm -f "tests/diag/$name.status"
            else
                echo "$status" >"tests/diag/$name.status"
            fi
            want=$status
        fi
        if [ ! -f "$expected" ]; then
            flunk "no $expected"
        elif ! cmp -s "$expected" "$work/err"; then
            [ -f "tests/diag/$name.bug" ] && flunk "known bug: $(cat "tests/diag/$name.bug")"
            flunk "stderr differs from $expected"
            diff -u "$expected" "$work/err" | cat -v | head -40
        fi
        want_status "$want"
        [ ! -s "$work/out" ] || flunk "validate wrote to stdout"
        cp "$work/err" "$work/text.err"
        json_form "$yaml" "$want"
    fi
    end
}

# ---- generated hostile cases: checked by pattern

# write NAME EXPR: writes $work/NAME.yaml, the bytes of the Python
# expression EXPR, in which `head` is the start of a valid effect.
write() {
    "$py" -c '
import sys
head = b"pfx: 1\nemitters:\n  flame:\n    rate: 10\n"
with open(sys.argv[1], "wb") as f:
    f.write(eval(sys.argv[2]))' "$work/$1.yaml" "$2"
}

# expect NAME STATUS PATTERN...: `pfx validate $work/NAME.yaml` exits
# STATUS and its stderr contains every PATTERN, a fixed string: one starting
# with ':' right after the file name (":4:12: error: "), any other anywhere.
# The JSON form must hold too. The text stderr is left in $work/text.err for
# further checks.
expect() {
    local f=$work/$1.yaml want=$2 p
    shift 2
    pfx_run validate "$f"
    cp "$work/err" "$work/text.err"
    finished || return
    want_status "$want"
    for p in "$@"; do
        case $p in :*) p=$f$p ;; esac
        grep -qF -- "$p" "$work/err" || flunk "stderr lacks '${p#"$f"}'"
    done
    [ "$check_ok" = 1 ] || head -c 2000 "$work/err" | head -20
    json_form "$f" "$want"
}

# errors_shown N: the text stderr has exactly N error headers.
errors_shown() {
    local n
    n=$(grep -c ': error: ' "$work/text.err")
    [ "$n" -eq "$1" ] || flunk "$n errors shown, expected $1"
}

# One function per case, gen_NAME; tests/CMakeLists.txt makes a CTest of
# each from these lines.
gen_huge() { # past the 16 MiB limit, by a long comment
    write huge 'head + b"# " + b"x" * (17 << 20) + b"\n"'
    expect huge 1 ": error: the file is larger than 16 MiB"
}
gen_limit() { # exactly at the limit: still read and validated
    write limit '(lambda body: body + b"x" * ((16 << 20) - len(body) - 1) + b"\n")(head + b"# ")'
    expect limit 0
}
gen_not_utf8() { # bytes that are not UTF-8 inside a scalar
    write not_utf8 'b"pfx: 1\nemitters:\n  flame:\n    color: \"\xff\xfe\"\n"'
    expect not_utf8 1 ":4:13: error: invalid leading UTF-8 octet (the file must be UTF-8 text)"
}
gen_nul_byte() { # a NUL byte after a value: a located error, at 4:12
    write nul_byte 'b"pfx: 1\nemitters:\n  flame:\n    rate: 5\x00\n"'
    expect nul_byte 1 ":4:12: error: " "NUL"
}
gen_many_diagnostics() { # 250 unknown keys: 200 diagnostics kept, the rest counted
    write many_diagnostics 'b"pfx: 1\n" + b"".join(b"unknown%d: 1\n" % i for i in range(250)) + head[7:]'
    expect many_diagnostics 1 ":2:1: error: unknown key 'unknown0' in the effect" \
        ": note: 50 more diagnostics not shown"
    errors_shown 200
}
gen_deep_mappings() { # 10,000 nested flow mappings
    write deep_mappings 'b"pfx: 1\ndeep: " + b"{a: " * 10000 + b"1" + b"}" * 10000 + b"\n"'
    expect deep_mappings 1 ":2:259: error: nesting deeper than 64 levels"
}
gen_long_utf8_value() { # a long non-ASCII value: the message quoting it is cut, never mid-character
    write long_utf8_value 'b"pfx: 1\nemitters:\n  flame:\n    rate: xy" + "\u00e9".encode() * 2000 + b"\n"'
    expect long_utf8_value 1 ":4:11: error: 'rate' must be a number, got 'xy"
}
gen_long_scalar() { # a 1 MB scalar value: one error
    write long_scalar 'b"pfx: 1\nemitters:\n  flame:\n    rate: " + b"9" * (1 << 20) + b"\n"'
    expect long_scalar 1 ":4:11: error: 'rate' must be a finite number"
    errors_shown 1
}

# bounded SECONDS KIB: tighter limits for the runs of one case, where the
# issue is time or memory (a parse or compile must stay linear in the file).
# Under AddressSanitizer the time is four times as long and the memory is
# not bounded (its shadow memory needs more).
bounded() {
    pfx_timeout=$1
    pfx_vm=$2
    if [ "$asan" = 1 ]; then
        pfx_timeout=$(($1 * 4))
        pfx_vm=unlimited
    fi
}

# Linear in the file: each of these took minutes or gigabytes when a check
# was quadratic or came after the work it bounds. 5 s and 500 MB each.
gen_keys_150000() { # one mapping of 150,000 keys (2 MB): the duplicate check is hashed
    write keys_150000 'head + b"    extra:\n" + b"".join(b"      k%d: 1\n" % i for i in range(150000))'
    bounded 5 500000
    expect keys_150000 1 ":5:5: error: unknown key 'extra' in emitter 'flame'"
    errors_shown 1
}
gen_keys_150000_same() { # 150,000 copies of one key: 200 diagnostics kept, the rest counted
    write keys_150000_same 'head + b"    extra:\n" + b"      k: 1\n" * 150000'
    bounded 5 500000
    expect keys_150000_same 1 ":7:7: error: duplicate key 'k'" ":6:7: note: 'k' first defined here" \
        "more diagnostics not shown"
    errors_shown 199
}
gen_keys_150000_unknown() { # 150,000 unknown keys of an emitter: no suggestion sought past the cap
    write keys_150000_unknown 'head + b"".join(b"    k%d: 1\n" % i for i in range(150000))'
    bounded 5 500000
    expect keys_150000_unknown 1 ":5:5: error: unknown key 'k0' in emitter 'flame'" \
        ": note: 149800 more diagnostics not shown"
}
gen_anchors_100000() { # 100,000 anchors, then 100,000 aliases of the first: anchors are hashed
    write anchors_100000 'head + b"    extra:\n" + b"".join(b"      - &a%d %d\n" % (i, i) for i in range(100000)) + b"      - *a0\n" * 100000'
    bounded 5 500000
    expect anchors_100000 1 ":5:5: error: unknown key 'extra' in emitter 'flame'"
    errors_shown 1
}
gen_emitters_150000() { # 150,000 emitters: the cap of 1024 is checked before compiling any
    write emitters_150000 'b"pfx: 1\nemitters:\n" + b"".join(b"  e%d: {}\n" % i for i in range(150000))'
    bounded 5 500000
    expect emitters_150000 1 ":3:3: error: an effect has at most 1024 emitters, got 150000"
    errors_shown 1
}
gen_bursts_150000() { # 150,000 bursts: the cap of 256 before reading any
    write bursts_150000 'head + b"    bursts:\n" + b"      - { time: 1, count: 1 }\n" * 150000'
    bounded 5 500000
    expect bursts_150000 1 ":6:7: error: an emitter has at most 256 bursts, got 150000"
    errors_shown 1
}

gen_mesh_fifo() { # a mesh file that is a FIFO with no writer: refused, not waited on
    mkfifo "$work/fifo.obj" || flunk "mkfifo failed"
    write mesh_fifo 'b"pfx: 1\nemitters:\n  flame:\n    shape: { type: mesh, file: fifo.obj }\n"'
    expect mesh_fifo 1 ":4:32: error: cannot open 'fifo.obj': not a regular file"
    errors_shown 1
}

generated_case() {
    begin "generated/$1"
    if declare -F "gen_$1" >/dev/null; then
        "gen_$1"
    else
        flunk "no generated case '$1' (a gen_$1 function in tests/diag/diag.sh)"
    fi
    end
}

# ---- every .expected, .status and .bug belongs to a case
stray_files() {
    local f
    begin stray
    for f in tests/diag/*.expected tests/diag/*.status tests/diag/*.bug; do
        [ -e "$f" ] || continue
        [ -f "${f%.*}.yaml" ] || flunk "$(basename "$f") has no ${f%.*}.yaml"
    done
    end
}

case $mode in
case)
    [ $# -gt 0 ] || set -- tests/diag/*.yaml
    for name in "$@"; do
        name=${name##*/}
        committed_case "${name%.yaml}"
    done
    ;;
generated)
    [ $# -gt 0 ] || set -- $(declare -F | sed -n 's/^declare -f gen_//p')
    for name in "$@"; do
        generated_case "$name"
    done
    ;;
stray) stray_files ;;
*)
    echo "usage: bash diag.sh PATH-TO-PFX SOURCE-DIR case|generated [NAME...]|stray" >&2
    exit 2
    ;;
esac
summary
