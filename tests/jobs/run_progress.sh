#!/usr/bin/env bash
# --progress json: every line on stderr that starts with '{' parses with
# Python's json module; one "frame" line per frame (each frame once, also
# with -j), "done" counting up to "total", then one "done" line with the
# exit status.
#
#   bash run_progress.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" progress "$@"
cd "$work" || exit 2
FIRE=$src/effects/fire.yaml

check() {
    "$py" - "$work/err" "$@" <<'PY'
import json, sys
path, first, last, status = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
lines = [l for l in open(path) if l.startswith("{")]
try:
    events = [json.loads(l) for l in lines]
except ValueError as e:
    print("FAIL a line is not JSON: %s" % e); sys.exit()
frames = [e for e in events if e.get("event") == "frame"]
done = [e for e in events if e.get("event") == "done"]
want = list(range(first, last + 1))
bad = []
if sorted(e["frame"] for e in frames) != want:
    bad.append("frames %s" % [e["frame"] for e in frames])
if [e["done"] for e in frames] != list(range(1, len(want) + 1)):
    bad.append("done does not count up")
if any(e["total"] != len(want) or e["particles"] < 0 or e["elapsed_s"] < 0 for e in frames):
    bad.append("a bad total, particles or elapsed_s")
if len(done) != 1 or events[-1] is not done[0] or done[0]["status"] != status:
    bad.append("the done line: %s" % done)
print(("FAIL " + "; ".join(bad)) if bad else
      "ok   %d frame lines and a done line with status %d" % (len(frames), status))
PY
}

begin "render --progress json"
pfx_run render "$FIRE" -o a --frames 3:9 --size 32x32 --progress json
want_status 0
stderr_has "pfx: rendered"
end
tally "$(check 3 9 0)"

begin "render --progress json -j 3"
pfx_run render "$FIRE" -o b --frames 3:9 --size 32x32 --progress json -j 3
want_status 0
end
tally "$(check 3 9 0)"

begin "a failed render ends with its status"
mkdir -p c/fire_0002.png
pfx_run render "$FIRE" -o c --frames 0:4 --size 32x32 --progress json
want_status 1
end
"$py" -c '
import json, sys
d = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
print("ok   the done line says status 1" if d and d[-1]["event"] == "done" and d[-1]["status"] == 1
      else "FAIL the last line: %r" % (d[-1:],))' "$work/err" >report
tally "$(cat report)"

begin "--progress takes only json"
pfx_run render "$FIRE" -o d --progress xml
want_status 2
stderr_has "--progress takes 'json', got 'xml'"
end

summary
