#!/usr/bin/env bash
# SIGINT and SIGTERM in the middle of a render or a bake: pfx exits with
# 130 or 143 and leaves no temporary file (.NAME.tmp-PID...) behind, and no
# manifest for the unfinished run.
#
#   bash run_signals.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" signals "$@"
cd "$work" || exit 2
FIRE=$src/effects/fire.yaml

# interrupt SIGNAL DIR ARGS...: starts pfx ARGS (SIGINT not ignored, as
# from a terminal: a background job of a script starts with SIGINT ignored,
# and pfx leaves an ignored signal ignored), waits until DIR holds a frame
# (so that writing is under way), sends SIGNAL, and sets $status.
interrupt() {
    local sig=$1 dir=$2
    shift 2
    env --default-signal=INT "$pfx" "$@" >/dev/null 2>"$work/err" &
    local pid=$! n=0
    until [ -n "$(ls -A "$dir" 2>/dev/null)" ] || [ $n -ge 600 ]; do
        sleep 0.05
        n=$((n + 1))
    done
    kill -"$sig" "$pid"
    wait "$pid"
    status=$?
}

begin "SIGINT during a render: status 130, no temporary file"
interrupt INT r1 render "$FIRE" -o r1 --size 512x512 -q
[ "$status" = 130 ] || flunk "exit status $status"
[ -z "$(find r1 -name '.*tmp*')" ] || flunk "left: $(find r1 -name '.*tmp*' | head -3)"
[ ! -e r1/fire.manifest.json ] || flunk "a manifest was written"
end

begin "SIGTERM during a render: status 143, no temporary file"
interrupt TERM r2 render "$FIRE" -o r2 --size 512x512 -q -j 2
[ "$status" = 143 ] || flunk "exit status $status"
[ -z "$(find r2 -name '.*tmp*')" ] || flunk "left: $(find r2 -name '.*tmp*' | head -3)"
end

begin "SIGINT during a bake: status 130, no temporary file"
mkdir -p b
interrupt INT b bake "$FIRE" -o b/fire.csv --fps 1000 -q
[ "$status" = 130 ] || flunk "exit status $status"
[ -z "$(find b -name '.*tmp*')" ] || flunk "left: $(find b -name '.*tmp*' | head -3)"
[ ! -e b/fire.csv ] || flunk "a partial bake is at b/fire.csv"
end

summary
