# The one vocabulary of the script tests, sourced by each of them with the
# arguments CTest gives it:
#
#   source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" NAME "$@"
#
# "$@" starts with PATH-TO-PFX SOURCE-DIR (a script may take more after
# them). It sets $pfx and $src (both absolute), $py (Debian's python3, which
# has python3-yaml and python3-jsonschema; not the first python3 on PATH)
# and $work, a scratch directory removed on exit. It does not change
# directory. The checks:
#
#   pass NAME, fail NAME [DETAIL]   a check made in one step
#   begin NAME ... end              a check made of several assertions; each
#                                   failed one calls `flunk PROBLEM`, and the
#                                   check counts once however many did
#   run NAME CMD...                 any command, quiet unless it fails
#   pfx_run ARGS...                 pfx, bounded, output kept for assertions
#   tally REPORT                    checks another program reported
#   summary                         the `N passed, M failed` line and status
#   skip REASON                     the test cannot run here: CTest's skip
#
# Every check prints one line, `ok   NAME` or `FAIL NAME: PROBLEM`.
if [ $# -lt 3 ]; then
    echo "usage: bash ${0##*/} PATH-TO-PFX SOURCE-DIR" >&2
    exit 2
fi
# Absolute paths by string alone: the diagnostics run this once per case.
case $2 in /*) pfx=$2 ;; *) pfx=$PWD/$2 ;; esac
case $3 in /*) src=$3 ;; *) src=$PWD/$3 ;; esac
pfx_dir=${pfx%/*}
if [ ! -x "$pfx" ] || [ ! -d "$src" ]; then
    echo "${0##*/}: no executable '$2' or no directory '$3'" >&2
    exit 2
fi
py=/usr/bin/python3
work=$(mktemp -d "${TMPDIR:-/tmp}/pfx-$1.XXXXXX") || exit 2
trap 'rm -rf "$work"' EXIT

passed=0
failed=0

# pass NAME, fail NAME [DETAIL]: a finished check. A DETAIL of several lines
# is printed below the FAIL line, indented.
pass() {
    passed=$((passed + 1))
    echo "ok   $1"
}
fail() {
    failed=$((failed + 1))
    case ${2-} in
    *$'\n'*)
        echo "FAIL $1"
        printf '%s\n' "$2" | sed 's/^/    /'
        ;;
    *) echo "FAIL $1${2:+: $2}" ;;
    esac
}

# begin NAME ... end: one check of several assertions. Each failed assertion
# calls `flunk PROBLEM`, which prints `FAIL NAME: PROBLEM`; `end` counts the
# check once, and when it failed after a pfx_run shows the head of that
# run's stdout and stderr.
check_name=
check_ok=1
check_ran=0
check_cmd=
begin() {
    check_name=$1
    check_ok=1
    check_ran=0
}
flunk() {
    check_ok=0
    echo "FAIL $check_name: $1"
}
end() {
    if [ "$check_ok" = 1 ]; then
        pass "$check_name"
    else
        failed=$((failed + 1))
        if [ "$check_ran" = 1 ]; then
            echo "  last run: pfx $check_cmd"
            echo "  stdout: $(head -c 400 "$work/out" | cat -v)"
            echo "  stderr: $(head -c 400 "$work/err" | cat -v)"
        fi
    fi
    check_name=
}

# run NAME CMD...: runs a command quietly, its output kept in $work/NAME.out
# and $work/NAME.err; on failure prints the command and its stderr and
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

# pfx_run ARGS...: runs pfx ARGS for at most $pfx_timeout seconds of wall
# time and $pfx_cpu seconds of CPU time, within $pfx_vm KiB of address
# space (a script may lower each), with stdout in $work/out, stderr in
# $work/err and the exit status in $status. Time bounds that a test asserts
# are CPU time: a loaded machine stretches the wall clock, not the work.
pfx_timeout=60
pfx_cpu=unlimited
pfx_vm=unlimited
pfx_run() {
    check_ran=1
    check_cmd=$*
    (
        ulimit -v "$pfx_vm" 2>/dev/null
        ulimit -t "$pfx_cpu" 2>/dev/null
        exec timeout "$pfx_timeout" "$pfx" "$@"
    ) >"$work/out" 2>"$work/err"
    status=$?
}

# Assertions on the last pfx_run, inside begin ... end.
# finished [WHAT]: pfx (the run named WHAT) ended by itself: not killed by
# the time bound (timeout's 124) nor by a signal (a crash, or an allocation
# failure turned into an abort; 128 and above). Returns 1 when not, so that
# later assertions on its output can be skipped.
finished() {
    if [ "$status" -eq 124 ]; then
        flunk "${1:+$1: }timed out after $pfx_timeout s"
        return 1
    fi
    if [ "$status" -eq 152 ] && [ "$pfx_cpu" != unlimited ]; then
        flunk "${1:+$1: }used more than $pfx_cpu s of CPU time (SIGXCPU)"
        return 1
    fi
    if [ "$status" -ge 128 ]; then
        flunk "${1:+$1: }killed by signal $((status - 128))"
        return 1
    fi
}
want_status() { [ "$status" -eq "$1" ] || flunk "exit status $status, expected $1"; }
stderr_has() { grep -qF -- "$1" "$work/err" || flunk "stderr lacks '$1'"; }
stdout_has() { grep -qF -- "$1" "$work/out" || flunk "stdout lacks '$1'"; }
stdout_empty() { [ ! -s "$work/out" ] || flunk "stdout is not empty"; }
stderr_empty() { [ ! -s "$work/err" ] || flunk "stderr is not empty"; }

# tally REPORT: prints the report of a helper program that made checks of
# its own, one `ok   NAME` or `FAIL NAME...` line each (indented details
# below), and counts them. A report with no check in it is a failure, and
# so is a helper that exited non-zero without a FAIL line (it stopped
# before its last check); call it as tally "$(helper ...)", or right after
# out=$(helper ...), so that $? is still the helper's status.
tally() {
    local status=$? n_ok n_fail
    printf '%s\n' "$1"
    n_ok=$(printf '%s\n' "$1" | grep -c '^ok   ')
    n_fail=$(printf '%s\n' "$1" | grep -c '^FAIL ')
    passed=$((passed + n_ok))
    failed=$((failed + n_fail))
    [ $((n_ok + n_fail)) -gt 0 ] || fail "the helper reported no check"
    # A helper that stops half-way (an exception, a timeout) has skipped the
    # checks after it: that fails even when every check it reached passed.
    [ "$status" -eq 0 ] || [ "$n_fail" -gt 0 ] ||
        fail "the helper exited with status $status after its last check"
}

# summary: the `N passed, M failed` line; the status is 0 only if none
# failed and something was checked.
summary() {
    echo "$passed passed, $failed failed"
    [ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
}

# skip REASON: what the test exists to check cannot be checked here (no
# GPU, no Slurm, a renderer not built): a `SKIP: REASON` line and exit 77,
# which tests/CMakeLists.txt names as SKIP_RETURN_CODE, so that CTest
# reports the test as skipped rather than passed. A check that already
# failed still fails the test.
skip() {
    if [ "$failed" -gt 0 ]; then
        summary
        exit
    fi
    echo "SKIP: $1"
    exit 77
}
