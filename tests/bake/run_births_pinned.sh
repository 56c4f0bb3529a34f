#!/usr/bin/env bash
# The bytes of births, pinned: CSV bakes of effects that draw every shape
# and emit_from mode, every direction mode, both spreads, uniform, Reeves
# and normal values, keyframed position and rotation with inherited
# velocity, bursts and rates, a loop whose periods start inside a step,
# sub-emitter children of every event (birth, death, hit with its normal,
# trail) with inherited velocity, a motion plan, a deflector with a random
# response, pools too small for the births (--max-particles), and pools
# large enough for two threads (8192 particles or more) with hundreds of
# births a step and bursts of thousands (batch).
#
# Recorded with the pfx of 59a96be, which drew and stepped each birth on
# its own; births now go in blocks (sim/birth.c, sim/newborn.c: all units
# of a block drawn first, then each stage one loop over its columns,
# vectorised), which must change no bit. Each bake is made on 1 and 2
# threads.
#
# A change here means births changed: a commit that changes them on
# purpose updates these and says why.
#
#   bash run_births_pinned.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" births_pinned "$@"
cd "$work" || exit 2

cat >shapes.yaml <<'EOF'
pfx: 1
duration: 1
fps: 24
seed: 5
forces:
  g: { type: gravity }
emitters:
  ell:
    shape: { type: ellipse, radii: [0.5, 0.2] }
    direction: inward
    spread: [40, 20]
    speed: {normal: [2, 0.5]}
    lifetime: {normal: [1, 0.2], clamp: [0.3, 2]}
    size: { start: [0.1, 0.2], end: [0.0, 0.05] }
    rate: 500
    forces: [g]
    gravity_scale: [0.5, 1.5]
  elledge:
    shape: { type: ellipse, radii: [0.5, 0.2], emit_from: edge }
    direction: normal
    spread: 10
    speed: [1, 2]
    lifetime: 1
    distance: [0, 0.1]
    rate: 400
    position: [{ t: 0, value: [0, 0, 0] }, { t: 1, value: [2, 1, 0] }]
    rotation: [{ t: 0, value: [0, 0, 0] }, { t: 1, value: [30, 360, 10] }]
    inherit_velocity: 1
  cone_n:
    shape: { type: cone, radius: 0.3, height: 0.5, angle: 30 }
    direction: normal
    spread: 5
    speed: 2
    lifetime: [0.5, 1]
    rate: 800
    bursts: [{ time: 0.2, count: 300 }, { time: 0.5, count: 150, cycles: 3, interval: 0.1 }]
  cone_s:
    shape: { type: cone, radius: 0.3, height: 0.5, emit_from: surface }
    direction: radial
    spread: 15
    speed: 1
    lifetime: 1
    rate: 300
    rotation: [20, 0, 45]
  sph_s:
    shape: { type: sphere, radius: 0.3, emit_from: surface }
    direction: tangent
    spread: 0
    speed: [1, 3]
    lifetime: 1
    rate: 300
    angle: [0, 360]
    spin: [-90, 90]
    color: { random: ["#ff0000", "#00ff00"] }
  sph_v:
    shape: { type: sphere, radius: 0.3, inner: 0.1 }
    direction: radial
    spread: 180
    speed: [1, 3]
    lifetime: 1
    rate: 0
    bursts: [{ time: 0, count: 1000 }, { time: 0.3, count: 700 }]
  hemi:
    shape: { type: hemisphere, radius: 0.3, inner: 0.05 }
    direction: inward
    spread: 20
    speed: [1, 3]
    lifetime: 1
    rate: 300
  cyl:
    shape: { type: cylinder, radius: 0.3, height: 1 }
    direction: normal
    spread: 20
    speed: [1, 3]
    lifetime: 1
    rate: 300
  pt:
    shape: { type: point }
    direction: [1, 1, 0]
    spread: 90
    speed: {mean: 2, var: 1}
    lifetime: 1
    rate: 2000
EOF
cat >children.yaml <<'EOF'
pfx: 1
duration: 1
fps: 24
seed: 9
forces:
  g: { type: gravity }
  pull: { type: attractor, center: [0, 1, 0], strength: 5, softening: 0.2 }
deflectors:
  floor: { type: plane, point: [0, -0.2, 0], normal: [0, 1, 0], response: bounce, resilience: [0.3, 0.6] }
emitters:
  rings:
    shape: { type: disc, radius: 0.5, inner: 0.2, arc: 270 }
    direction: radial
    speed: [1, 2]
    lifetime: 1
    rate: 400
    forces: [g, pull]
    deflectors: [floor]
  rim:
    shape: { type: disc, radius: 0.5, emit_from: edge }
    direction: normal
    speed: [1, 2]
    lifetime: 1
    rate: 0
    bursts: [{ time: 0.1, count: 500 }]
    forces: [g, pull]
    deflectors: [floor]
    on_hit: { emit: kid, count: 2, inherit: [velocity] }
    on_birth: { emit: kid, count: 1, probability: 0.5 }
  boxs:
    shape: { type: box, size: [1, 0.5, 0.2], emit_from: surface }
    direction: normal
    speed: [1, 2]
    lifetime: 1
    rate: 400
    forces: [g]
    deflectors: [floor]
    on_death: { emit: kid, count: [1, 3] }
  boxv:
    shape: { type: box, size: [1, 0.5, 0.2] }
    direction: radial
    speed: [1, 2]
    lifetime: 0.5
    rate: 400
    trail: { emit: kid, rate: 20 }
  rect:
    shape: { type: rect, size: [1, 0.5] }
    speed: [1, 2]
    lifetime: 1
    rate: 300
  rect_e:
    shape: { type: rect, size: [1, 0.5], emit_from: edge }
    direction: normal
    speed: [1, 2]
    lifetime: 1
    rate: 300
  line:
    shape: { type: line, from: [0, 0, 0], to: [1, 1, 0] }
    direction: normal
    speed: [1, 2]
    lifetime: 1
    rate: 300
  kid:
    shape: { type: sphere, radius: 0.05 }
    direction: normal
    spread: 30
    speed: [0.5, 1]
    lifetime: [0.2, 0.4]
    rate: 0
    forces: [g]
    inherit_velocity: 0.5
EOF
cat >batch.yaml <<'EOF'
pfx: 1
duration: 0.5
fps: 24
seed: 21
forces:
  g: { type: gravity }
  pull: { type: attractor, center: [0, 1, 0], strength: 5, softening: 0.2 }
deflectors:
  floor: { type: plane, point: [0, -0.5, 0], normal: [0, 1, 0], response: bounce, resilience: [0.3, 0.6] }
emitters:
  spray:
    shape: { type: sphere, radius: 0.3 }
    spread: 30
    speed: [2, 4]
    lifetime: [0.3, 0.6]
    rate: 30000
    size: [0.01, 0.02]
    forces: [g]
  blast:
    shape: { type: cone, radius: 0.2, height: 0.4 }
    direction: normal
    spread: 10
    speed: [1, 3]
    lifetime: 1
    rate: 0
    bursts: [{ time: 0.05, count: 10000 }, { time: 0.2, count: 5000 }]
    forces: [g, pull]
  rain:
    shape: { type: disc, radius: 1 }
    direction: [0, -1, 0]
    speed: [1, 2]
    lifetime: [0.2, 0.5]
    rate: 20000
    forces: [g]
    deflectors: [floor]
    position: [{ t: 0, value: [0, 0, 0] }, { t: 0.5, value: [1, 0.5, 0] }]
    on_hit: { emit: splash, count: 1, probability: 0.3 }
  splash:
    shape: { type: point }
    direction: normal
    spread: 40
    speed: 1
    lifetime: 0.2
    rate: 0
    forces: [g]
EOF
cat >loop.yaml <<'EOF'
pfx: 1
duration: 0.5
loop: true
fps: 24
seed: 11
sim:
  rate: 30
forces:
  g: { type: gravity }
  air: { type: drag, k: 0.8 }
emitters:
  ring:
    shape: { type: sphere, radius: 0.4 }
    spread: 25
    speed: [1, 2]
    lifetime: [0.2, 0.45]
    rate: 2500
    size: [0.01, 0.03]
    forces: [g, air]
  fan:
    shape: { type: cone, radius: 0.2, height: 0.3 }
    direction: tangent
    spread: 60
    speed: {normal: [1, 0.3]}
    lifetime: 0.3
    rate: 0
    bursts: [{ time: 0.1, count: 200, cycles: 2, interval: 0.2 }]
EOF

# effect options sha256
pinned=(
    "shapes - b66ff0bb94c6cc76b07467cea26a55e067512975b4e6d1c7bc998a39e59464b2"
    "children - cf103d3db2dba7181b6e3f6812ad46091673f87b925aca021f5f342194dffcd8"
    "children --max-particles=600 d6daa5624de6aec380521ede6392373fff71ee20454eedf6935e73aede300969"
    "loop - aafab241ca9fd48f02d246af2206463e3a170f060a3a1906977582ebfa268e29"
    "batch --frames=0:5 e058b8aae9beb15c5663e7c89eafd539aa02d3e8b7832b0648fe9037b9de1288"
)

for p in "${pinned[@]}"; do
    read -r effect opts want <<<"$p"
    [ "$opts" = - ] && opts=
    for threads in 1 2; do
        begin "$effect $opts on $threads threads: the bytes of 59a96be"
        pfx_run bake "$effect.yaml" -o "$effect.csv" --threads "$threads" --force -q $opts
        if finished && want_status 0; then
            got=$(sha256sum <"$effect.csv" | cut -d' ' -f1)
            [ "$got" = "$want" ] || flunk "sha256 $got"
        fi
        end
    done
done

summary
