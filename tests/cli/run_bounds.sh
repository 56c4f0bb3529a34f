#!/usr/bin/env bash
# Work and memory bounded whatever the file says: effects that once ran for
# weeks or out of memory without a word must now end fast with a warning or
# a clean error, or run within a stated bound (issue 12). Each check names
# the input and the bound it asserts; the time and the peak resident memory
# of a run are measured around it (getrusage). Under AddressSanitizer the
# memory bounds are not asserted (its shadow memory needs more) and the time
# bounds are four times as long.
#
#   bash run_bounds.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" bounds "$@"
cd "$src" || exit 2

asan=0
grep -q __asan_init "$pfx" 2>/dev/null && asan=1

# measured ARGS...: runs pfx ARGS like pfx_run (stdout in $work/out, stderr
# in $work/err, $status) and keeps its wall time in $secs and its peak
# resident memory in $peak_kb.
measured() {
    check_ran=1
    check_cmd=$*
    read -r status secs peak_kb < <("$py" -c '
import resource, subprocess, sys, time
t = time.monotonic()
with open(sys.argv[1], "wb") as out, open(sys.argv[2], "wb") as err:
    try:
        st = subprocess.run(sys.argv[4:], stdout=out, stderr=err, timeout=float(sys.argv[3])).returncode
        st = st if st >= 0 else 128 - st
    except subprocess.TimeoutExpired:
        st = 124
print(st, "%.2f" % (time.monotonic() - t), resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
' "$work/out" "$work/err" "$pfx_timeout" "$pfx" "$@")
}

# within SECONDS MB: the last measured run took under SECONDS (four times
# as long under ASan) and, without ASan, peaked under MB megabytes.
within() {
    local s=$1
    [ "$asan" = 1 ] && s=$(($1 * 4))
    awk -v a="$secs" -v b="$s" 'BEGIN { exit !(a < b) }' || flunk "took $secs s, bound $s s"
    [ "$asan" = 1 ] || [ "$peak_kb" -lt $(($2 * 1024)) ] || flunk "peaked at $((peak_kb / 1024)) MB, bound $2 MB"
}

# ---- spawn queues: no larger than their target pools
# Two emitters in a sub-emitter cycle, depth 16, each laying a trail and
# bursting on death into the other: a thousand million births a second. The
# queues were sized from the parents' worst-case events (3.26 GB at frame 12
# with the default budget; 166 MB with a budget of 100,000); bounded by the
# target pools they stay near the pools' size, and the births past them are
# counted as dropped.
cat >"$work/cycle.yaml" <<'YAML'
pfx: 1
duration: 1
emitters:
  a:
    rate: 1000
    lifetime: 0.05
    trail: { emit: b, rate: 1000 }
    on_death: { emit: b, count: 100, depth: 16 }
  b:
    lifetime: 0.05
    trail: { emit: a, rate: 1000, depth: 16 }
    on_death: { emit: a, count: 100, depth: 16 }
YAML
begin "a sub-emitter cycle at depth 16: queues bounded by the pools (5 s, 120 MB)"
measured bake "$work/cycle.yaml" -o "$work/cycle.csv" --frames 12:12 --max-particles 100000
if finished; then
    want_status 0
    within 5 120
    stderr_has "pfx: note: emitter 'a' dropped "
    stderr_has "pfx: note: emitter 'b' dropped "
    [ -s "$work/cycle.csv" ] || flunk "no CSV"
fi
end

summary
