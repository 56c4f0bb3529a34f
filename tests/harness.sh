# Sourced by the script tests: a scratch directory removed on exit ($work),
# pass/fail counters with one line per check, run (a command whose output is
# kept and shown only when it fails), and the closing summary line.
#   source "$src/tests/harness.sh" NAME
work=$(mktemp -d "${TMPDIR:-/tmp}/pfx-$1.XXXXXX") || exit 1
trap 'rm -rf "$work"' EXIT

passed=0
failed=0
pass() { passed=$((passed + 1)); echo "ok   $1"; }
fail() { failed=$((failed + 1)); echo "FAIL $1${2:+: $2}"; }

# run NAME CMD...: runs a command quietly; on failure prints its stderr and
# returns 1.
run() {
    local name=$1
    shift
    if ! "$@" >"$work/$name.out" 2>"$work/$name.err"; then
        echo "  command failed: $*" >&2
        sed 's/^/  | /' "$work/$name.err" >&2
        return 1
    fi
}

# summary: the `N passed, M failed` line; the status is 0 only if none failed.
summary() {
    echo "$passed passed, $failed failed"
    [ "$failed" -eq 0 ]
}
