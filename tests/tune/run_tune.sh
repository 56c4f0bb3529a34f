#!/usr/bin/env bash
# pfx tune through the command line: closed-form scenes (projectile, linear
# drag, spring, orbit) whose measured errors must equal each integrator's
# own error computed in check_tune.py; a recommendation that, applied with
# --set, meets the tolerance when tune checks again; a method unstable at
# the file's rate flagged with its rule; the chart, CSV and JSON parsed.
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" tune "$@"
CHECK="$src/tests/tune/check_tune.py"

# scene NAME FORCES [INTEGRATOR [EXTRA-EMITTER-KEYS]]: one particle from the
# origin (or x = 1 for spring and orbit), frames every 0.1 s to 1.9 s, at
# 80 steps/s, so that every ladder rate (10 to 640) falls on the frames.
scene() {
    local name=$1 forces=$2 integ=${3:-auto} pos=${4:-[0, 0, 0]} dir=${5:-[1, 0, 0]} speed=${6:-3}
    cat >"$work/$name.yaml" <<EOF
pfx: 1
duration: 2
fps: 10
sim: { rate: 80, integrator: $integ }
camera: { position: [0, 0, 10], target: [0, 0, 0], up: [0, 1, 0], ortho: 40 }
image: { size: [400, 400] }
forces:
$forces
emitters:
  one:
    shape: { type: point }
    position: $pos
    bursts: [{ time: 0, count: 1 }]
    direction: $dir
    spread: 0
    speed: $speed
    lifetime: 100
EOF
}

# tune NAME ARGS...: pfx tune into $work/NAME; fails the check when pfx does.
tune() {
    local name=$1
    shift
    if ! "$pfx" tune "$work/$name.yaml" -o "$work/$name" -q "$@" >"$work/$name.out" 2>&1; then
        fail "$name: pfx tune exited non-zero: $(head -c 600 "$work/$name.out")"
        return 1
    fi
}

# The closed-form scenes run at a tolerance no run meets (1e-9 m, below
# float rounding), so nothing is pruned for cost and every integrator runs
# at every rate: the same runs whatever the timings.
scene projectile "  g: { type: gravity, accel: [0, -9.81, 0] }"
tune projectile --tolerance 1e-9m && tally "$("$py" "$CHECK" errors projectile "$work/projectile")"
scene drag "  air: { type: drag, k: 2 }"
tune drag --tolerance 1e-9m && tally "$("$py" "$CHECK" errors drag "$work/drag")"
scene spring "  pull: { type: spring, anchor: [0, 0, 0], k: 4 }" auto "[1, 0, 0]" "[1, 0, 0]" 0
tune spring --tolerance 1e-9m && tally "$("$py" "$CHECK" errors spring "$work/spring")"
scene orbit "  sun: { type: attractor, center: [0, 0, 0], strength: 4, softening: 0 }" auto \
    "[1, 0, 0]" "[0, 1, 0]" 2
tune orbit --tolerance 1e-9m && tally "$("$py" "$CHECK" errors orbit "$work/orbit")"
tally "$("$py" "$CHECK" files "$work/orbit")"

# The recommendation for the spring at 0.5 px, applied with --set: tune
# then finds the current setting within the tolerance (0.5 px = 5 cm here)
# and recommends it.
tune spring --tolerance 0.5px && {
    sets=$("$py" -c '
import json, sys
d = json.load(open(sys.argv[1]))
r = d["runs"][d["recommended"]]
print("--set sim.integrator=%s --set sim.rate=%r" % (r["integrator"], r["rate"])
      + (" --set sim.substeps=%d" % r["substeps"] if r["substeps"] else ""))' "$work/spring/tune.json")
    cp "$work/spring.yaml" "$work/applied.yaml"
    # shellcheck disable=SC2086
    tune applied --tolerance 0.5px $sets && tally "$("$py" "$CHECK" within "$work/applied" 0.05)"
}

# A stiff spring (omega = 100 /s) under symplectic Euler at 120 steps/s
# (omega h = 0.83, stable): explicit Euler at that rate grows by
# |1 + 0.83i| = 1.3 a step and blows up; the stability rule predicts it.
scene stiff "  pull: { type: spring, anchor: [0, 0, 0], k: 10000 }" symplectic "[1, 0, 0]" \
    "[1, 0, 0]" 0
sed -i 's/rate: 80/rate: 120/' "$work/stiff.yaml"
tune stiff && tally "$("$py" "$CHECK" unstable "$work/stiff" euler 120)"

# sim.tolerance in pixels: 0.01 px through an orthographic camera 40 m tall
# over 400 px is 1 mm; over the particle's 2 s of life, 5e-4 m/s. auto
# chooses the same substeps from either spelling (and others from 1 px =
# 0.05 m/s), and a tune at 0.01 px finds auto's own run within it.
scene pixels "  pull: { type: spring, anchor: [0, 0, 0], k: 4 }" auto "[1, 0, 0]" "[1, 0, 0]" 0
sed -i 's/rate: 80, /rate: 10, tolerance: 0.01px, /; s/lifetime: 100/lifetime: 2/' "$work/pixels.yaml"
begin "sim.tolerance 0.01px is 5e-4 m/s to auto here"
line() { "$pfx" info "$work/pixels.yaml" --set "sim.tolerance=$1" 2>&1 | grep 'integrator:'; }
px=$(line 0.01px) ms=$(line 5e-4) coarse=$(line 1px) coarse_ms=$(line 0.05)
[ -n "$px" ] || flunk "no integrator line from pfx info"
[ "$px" = "$ms" ] || flunk "0.01px: '$px'; 5e-4: '$ms'"
[ "$coarse" = "$coarse_ms" ] || flunk "1px: '$coarse'; 0.05: '$coarse_ms'"
[ "$px" != "$coarse" ] || flunk "0.01px and 1px choose alike: '$px'"
end
# Through a perspective camera: fov 60 at 10 m from the emitter, one pixel
# of 400 spans 2 x 10 x tan(30 deg) / 400 = 0.0288675 m, so 0.01 px over
# the 2 s life is 1.443376e-4 m/s.
sed 's/ortho: 40 }/fov: 60 }/' "$work/pixels.yaml" >"$work/perspective.yaml"
begin "sim.tolerance 0.01px through a perspective camera is 1.443376e-4 m/s"
px=$("$pfx" info "$work/perspective.yaml" 2>&1 | grep 'integrator:')
ms=$("$pfx" info "$work/perspective.yaml" --set sim.tolerance=1.443376e-4 2>&1 | grep 'integrator:')
[ -n "$px" ] && [ "$px" = "$ms" ] || flunk "0.01px: '$px'; 1.443376e-4: '$ms'"
end
tune pixels --tolerance 0.01px && tally "$("$py" "$CHECK" within "$work/pixels" 0.001)"

# What else the scene pays for. A red alpha-blended particle 0.1 m across
# (1 px) at 40 m/s leaves the 400 px (40 m) image past x = 20.05 m, at
# 0.50125 s: on screen for frames 0 to 5, off for 6 to 19, 14 of 20
# particle-frames; one colour under alpha blending needs no depth sort.
# The spring scene pays for steps a frame beyond need: its saving is that
# of the recommended rate over the file's 80 steps/s.
scene offscreen "  none: { type: drag, k: 0 }" auto "[0, 0, 0]" "[1, 0, 0]" 40
printf '    blend: alpha\n    size: 0.1\n    color: "#ff0000"\n' >>"$work/offscreen.yaml"
tune offscreen && tally "$("$py" "$CHECK" costs "$work/offscreen" 0.7 no)"
cat >>"$work/spring.yaml" <<'EOF'
    blend: alpha
    color: "#00ff00"
EOF
tune spring --tolerance 1mm && tally "$("$py" "$CHECK" costs "$work/spring" none steps)"

# A wrapping box (bounds: wrap, 2 m): 200 particles under linear drag
# towards a 3 m/s fall cross its faces again and again, so at some frame
# one run has wrapped a particle and another, a hair behind, has not: the
# two are a box size apart, yet the particle is where it should be. tune
# compares positions modulo the wrap (the shortest displacement within
# the box), so it reports the true error: the exact integrator, the closed
# form of linear drag, is off the reference by float rounding only
# (< 1e-4 m), and no run of a second-order scheme is near the box size
# (< 0.05 m; euler and symplectic, first order, are 0.6 m off at 10
# steps/s on their own).
cat >"$work/wrap.yaml" <<'EOF'
pfx: 1
duration: 2
fps: 10
sim: { rate: 80, integrator: midpoint }
camera: { position: [0, 0, 10], target: [0, 0, 0], up: [0, 1, 0], ortho: 4 }
image: { size: [400, 400] }
forces:
  air: { type: drag, k: 2, wind: [0, -3, 0] }
emitters:
  rain:
    shape: { type: box, size: [2, 2, 0] }
    bursts: [{ time: 0, count: 200 }]
    direction: [1, 0.5, 0]
    spread: 30
    speed: [1, 4]
    lifetime: 100
    bounds: { mode: wrap, box: { center: [0, 0, 0], size: [2, 2, 2] } }
EOF
tune wrap --tolerance 1e-9m && {
    out=$("$py" - "$work/wrap/tune.json" 2>&1 <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
runs = [r for r in d["runs"] if r["status"] == "ok"]
exact = max(r["err_max_m"] for r in runs if r["integrator"] == "exact")
worst = max(r["err_max_m"] for r in runs if r["integrator"] not in ("euler", "symplectic"))
print("wrap: exact off the reference by %.3g m, the worst second-order run by %.3g m (box 2 m)"
      % (exact, worst))
sys.exit(0 if exact < 1e-4 and worst < 0.05 else 1)
EOF
    ) && pass "$out" || fail "$out"
}

# Usage and input errors: exit 2 for a tolerance without a unit or not
# above 0, no -o, two files; exit 1 for a file that is not there, with
# nothing written.
for bad in "--tolerance 5" "--tolerance 0px" "--tolerance -1mm" "--tolerance 2ft"; do
    begin "tune $bad: a usage error"
    # shellcheck disable=SC2086
    pfx_run tune "$work/spring.yaml" -o "$work/bad" $bad
    want_status 2
    stderr_has "--tolerance takes a number above 0 and a unit"
    [ ! -e "$work/bad" ] || flunk "it made $work/bad"
    end
done
# One file named two ways by two emitters is read once (shared pixels),
# but each emitter's advice quotes the name as that emitter wrote it.
"$py" -c "from PIL import Image; Image.new('RGBA', (256, 256), (255,) * 4).save('$work/w.png')"
cat >"$work/two_names.yaml" <<'EOF'
pfx: 1
duration: 0.5
fps: 10
camera: { position: [0, 0, 5], target: [0, 0, 0], ortho: 2 }
image: { size: [64, 64] }
emitters:
  a: { rate: 20, lifetime: 1, size: 0.05, texture: w.png }
  b: { rate: 20, lifetime: 1, size: 0.05, texture: ./w.png }
EOF
begin "a shared texture keeps each emitter's own name in the advice"
pfx_run tune "$work/two_names.yaml" -o "$work/two_names"
want_status 0
grep -qF "emitter 'a': texture 'w.png' has 256px cells" "$work/two_names/tune.json" ||
    flunk "no advice for a's 'w.png'"
grep -qF "emitter 'b': texture './w.png' has 256px cells" "$work/two_names/tune.json" ||
    flunk "b's advice names $(grep -o "emitter 'b': texture '[^']*'" "$work/two_names/tune.json")"
end
# The file is read once: every run of the ladder compiles the same bytes
# (inotify counts the opens; each run opened it again before, and the
# file's own setting three more times).
begin "tune reads the effect file once, however many settings it compiles"
opens=$("$py" "$src/tests/jobs/count_opens.py" "$work/projectile.yaml" "$pfx" tune \
    "$work/projectile.yaml" -o "$work/once" -q --tolerance 1e-9m)
[ "$opens" = "1 0" ] || flunk "opens and status: $opens, want '1 0'"
runs=$("$py" -c 'import json, sys; print(len(json.load(open(sys.argv[1]))["runs"]))' \
    "$work/once/tune.json")
[ "$runs" -gt 10 ] || flunk "$runs runs only"
end

begin "tune --frames with a step: a usage error"
pfx_run tune "$work/spring.yaml" -o "$work/bad" --frames 0:9:2
want_status 2
stderr_has "it takes no step"
end
begin "tune without -o: a usage error"
pfx_run tune "$work/spring.yaml"
want_status 2
stderr_has "tune needs -o DIR"
end
begin "tune of a missing file: exit 1, nothing written"
pfx_run tune "$work/missing.yaml" -o "$work/missing"
want_status 1
stderr_has "missing.yaml"
[ ! -e "$work/missing/tune.csv" ] || flunk "it wrote tune.csv"
end

summary
