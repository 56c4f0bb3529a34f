#!/usr/bin/env bash
# The memory estimate of `pfx info --format json` bounds a real render: the
# peak RSS of `pfx render` (getrusage of the child, ru_maxrss) is at most the
# estimate plus a fixed slack for the libraries, for three effects (2e5
# alpha-blended sprites sorted every frame, in several blocks of the
# threaded sort; fire, textured; a ribbon swipe) at 1 and 2 threads and two
# sizes. The slack is the peak of rendering an effect of one particle
# (Mesa's llvmpipe, LLVM, the GL context and the libraries pfx links, about
# 75 MB on Debian 12), plus 24 MiB for the shader variants llvmpipe compiles
# for looks beyond that one (up to 18 MB measured, for the ribbons). Also:
# the JSON's parts add up to its total, the pools part is the emitters'
# capacity x bytes a particle, the per-thread part scales with --threads,
# and the crowd's frames are the same bytes at 1 and 2 threads.
#
#   bash run_memory.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" memory "$@"
cd "$work" || exit 2
CROWD=$src/tests/jobs/memory_crowd.yaml

# peak_kib OUT ARGS...: runs pfx ARGS, writes its peak RSS in KiB to OUT;
# false when pfx fails.
peak_kib() {
    local out=$1
    shift
    "$py" - "$out" "$pfx" "$@" <<'PY'
import resource, subprocess, sys
r = subprocess.run(sys.argv[2:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
sys.stderr.write(r.stderr.decode(errors="replace"))
open(sys.argv[1], "w").write("%d\n" % resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
sys.exit(r.returncode)
PY
}

cat >empty.yaml <<'YAML'
pfx: 1
duration: 0.2
fps: 10
image: { size: [128, 128] }
emitters:
  one: { rate: 1, lifetime: 0.5, blend: alpha }
YAML
run "empty render" peak_kib empty.kib render empty.yaml -o empty --threads 1 -q || exit 1
slack=$(($(cat empty.kib) + 24 * 1024))
begin "the libraries' own peak is plausible (under 256 MiB)"
(($(cat empty.kib) < 256 * 1024)) || flunk "an effect of one particle peaked at $(cat empty.kib) KiB"
end

# check NAME EFFECT SIZE THREADS FRAMES
check() {
    local name=$1 effect=$2 size=$3 threads=$4 frames=$5
    begin "$name: peak RSS <= estimate + $((slack / 1024)) MiB ($size, $threads threads)"
    if ! "$pfx" info --format json --size "$size" --threads "$threads" "$effect" >"$name.json"; then
        flunk "pfx info failed"
    elif ! peak_kib "$name.kib" render "$effect" -o "$name" --size "$size" --threads "$threads" \
        --frames "$frames" -q --force 2>"$name.err"; then
        flunk "render failed: $(head -c 300 "$name.err")"
    else
        "$py" - "$name.json" "$(cat "$name.kib")" "$slack" <<'PY' || flunk "$(cat "$name.why")"
import json, sys
d = json.load(open(sys.argv[1]))
rss, slack = int(sys.argv[2]) * 1024, int(sys.argv[3]) * 1024
est = d["memory"]["total_bytes"]
print("  %s: peak %.1f MiB, estimate %.1f MiB + slack %.1f MiB" % (sys.argv[1], rss / 2**20, est / 2**20, slack / 2**20))
if rss > est + slack:
    open(sys.argv[1][:-5] + ".why", "w").write("peak %d bytes over estimate %d + slack %d" % (rss, est, slack))
    sys.exit(1)
PY
    fi
    end
}

check crowd_1 "$CROWD" 128x128 1 0:1
check crowd_2 "$CROWD" 128x128 2 0:1
check crowd_big "$CROWD" 320x240 2 0:1
check fire_1 "$src/effects/fire.yaml" 256x256 1 20:24
check fire_2 "$src/effects/fire.yaml" 512x512 2 20:24
check swipe_2 "$src/effects/sword_swipe.yaml" 256x256 2 5:9

begin "crowd: 1 and 2 threads draw the same bytes (the sort's order)"
for f in 0 1; do
    name=$(printf 'memory_crowd_%04d.png' "$f")
    [[ -s crowd_1/$name ]] || flunk "no $name"
    cmp -s "crowd_1/$name" "crowd_2/$name" || flunk "$name differs"
done
end

begin "the JSON: parts sum to the total, pools = capacity x bytes, per thread x threads"
"$py" - crowd_1.json crowd_2.json <<'PY' || flunk "$(cat why)"
import json, sys
one, two = (json.load(open(p)) for p in sys.argv[1:3])
bad = []
for d in (one, two):
    m = d["memory"]
    if abs(sum(m["parts"].values()) - m["total_bytes"]) > 1:
        bad.append("parts sum to %d, total %d" % (sum(m["parts"].values()), m["total_bytes"]))
    pools = sum(e["capacity"] * e["bytes_per_particle"] for e in d["emitters"])
    if m["parts"]["pools"] != pools or m["parts"]["view"] != pools:
        bad.append("pools %d, view %d, emitters say %d" % (m["parts"]["pools"], m["parts"]["view"], pools))
    # 2e5 alpha-blended sprites: keys, indices and a copy to sort, at least 80 bytes each.
    if not d["depth_sort"] or m["parts"]["sort"] < 80 * 200000:
        bad.append("sort scratch %d for 2e5 sprites" % m["parts"]["sort"])
    if m["bound_bytes"] != 2 * pools + m["threads"] * m["per_thread_bytes"]:
        bad.append("bound %d" % m["bound_bytes"])
if (one["memory"]["threads"], two["memory"]["threads"]) != (1, 2) or \
        two["memory"]["parts"]["encoders"] != 2 * one["memory"]["parts"]["encoders"] or \
        one["memory"]["per_thread_bytes"] != two["memory"]["per_thread_bytes"]:
    bad.append("encoders %s vs %s" % (one["memory"]["parts"]["encoders"], two["memory"]["parts"]["encoders"]))
open("why", "w").write("; ".join(bad))
sys.exit(1 if bad else 0)
PY
end

summary
