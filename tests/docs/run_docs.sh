# Docs test: man pages lint clean, every --help option is in pfx.1, the schema is valid and
# agrees with pfx on effects/*.yaml and bad files, every key compile.c accepts is described in
# pfx-effect.5, and the pages' examples are true.
#
# Usage: bash run_docs.sh <path-to-pfx> <source-dir>   (run by CTest)
# The schema checks use Debian's python3-jsonschema and python3-yaml, which
# belong to /usr/bin/python3 (the harness's $py).
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" docs "$@"
man1=$src/man/pfx.1
man5=$src/man/pfx-effect.5
schema=$src/schemas/pfx-effect.schema.json
compile_c=$src/src/compile/compile.c

# The sections of pfx-effect.5 where top-level and emitter keys must each
# have their own tagged paragraph.
top_section="TOP-LEVEL KEYS"
emitter_section="EMITTERS"

for f in "$pfx" "$man1" "$man5" "$schema" "$compile_c"; do
    if [ ! -e "$f" ]; then
        fail "missing $f"
    fi
done
if [ "$failed" -gt 0 ]; then
    summary
    exit
fi

# Roff source -> plain text for grepping: hyphen and quote escapes become the
# characters they print, font changes and zero-width escapes go.
deroff() {
    sed -e 's/\\-/-/g' -e 's/\\(dq/"/g' -e 's/\\(aq/'"'"'/g' -e 's/\\(ha/^/g' \
        -e 's/\\(ti/~/g' -e 's/\\(mu/x/g' -e 's/\\f[BIRP]//g' -e 's/\\&//g' -e 's/\\e/\\/g' "$@"
}

# The lines of the .EX/.EE blocks of section $2 of page $1, each block ended
# by a line "@@END@@", de-roffed.
examples_of() {
    awk -v want="$2" '
        /^\.SH / { sec = substr($0, 5); gsub(/"/, "", sec); next }
        sec != want { next }
        /^\.EX/ { inex = 1; next }
        /^\.EE/ { if (inex) print "@@END@@"; inex = 0; next }
        inex { print }
    ' "$1" | deroff
}

# Writes block number $2 (from 1) of the examples_of output in $1 to stdout.
nth_block() {
    awk -v n="$2" '/^@@END@@$/ { k++; next } k == n - 1 { print }' "$1"
}

# --- (a) the man pages lint clean -----------------------------------------
for page in "$man1" "$man5"; do
    name=${page#"$src"/}
    linted=false
    if command -v mandoc >/dev/null 2>&1; then
        out=$(mandoc -T lint -W warning "$page" 2>&1)
        rc=$?
        if [ $rc -eq 0 ] && [ -z "$out" ]; then
            pass "mandoc -T lint -W warning $name is clean"
        else
            fail "mandoc -T lint -W warning $name (status $rc)" "$out"
        fi
        linted=true
    fi
    if command -v groff >/dev/null 2>&1; then
        out=$(groff -ww -z -man "$page" 2>&1)
        rc=$?
        if [ $rc -eq 0 ] && [ -z "$out" ]; then
            pass "groff -ww -z -man $name is clean"
        else
            fail "groff -ww -z -man $name (status $rc)" "$out"
        fi
        linted=true
    fi
    if ! $linted; then
        fail "cannot lint $name: neither mandoc nor groff is installed (apt-get install mandoc)"
    fi
done

# --- (b) every option and command of `pfx --help` is in pfx.1 --------------
help=$("$pfx" --help 2>&1)
rc=$?
if [ $rc -ne 0 ]; then
    fail "pfx --help exits $rc, not 0" "$help"
fi
man1_text=$(deroff "$man1")
long_opts=$(printf '%s\n' "$help" | grep -oE -- '--[a-z][a-z0-9-]*' | sort -u)
short_opts=$(printf '%s\n' "$help" | grep -oE -- '(^|[[ ,|])-[A-Za-z]([], |]|$)' |
    grep -oE -- '-[A-Za-z]' | sort -u)
commands=$(printf '%s\n' "$help" | awk '/^commands:/ { on = 1; next } on && NF == 0 { on = 0 }
    on { print $1 }')
if [ -z "$long_opts" ] || [ -z "$short_opts" ] || [ -z "$commands" ]; then
    fail "could not find the long options, short options and commands in pfx --help" "$help"
else
    missing=""
    for opt in $long_opts $short_opts; do
        # The option as a word of its own: -o must not match inside --output.
        if ! printf '%s\n' "$man1_text" | grep -qE -- "(^|[^-[:alnum:]])$opt([^-[:alnum:]]|$)"; then
            missing="$missing $opt"
        fi
    done
    n=$(echo $long_opts $short_opts | wc -w)
    if [ -z "$missing" ]; then
        pass "all $n options of pfx --help are in man/pfx.1"
    else
        fail "options of pfx --help missing from man/pfx.1:$missing"
    fi
    missing=""
    for cmd in $commands; do
        if ! grep -qE "^\.BI? \"?$cmd( |\"|$)" "$man1"; then
            missing="$missing $cmd"
        fi
    done
    if [ -z "$missing" ]; then
        pass "all commands of pfx --help ($(echo $commands)) are in man/pfx.1"
    else
        fail "commands of pfx --help missing from man/pfx.1:$missing"
    fi
fi

# --- (c), (d) the schema: valid, accepts the examples, rejects bad files ----
# The same documents also go through `pfx validate`, so the test data is
# known to be good or bad by the compiler's own judgement.
examples_of "$man5" EXAMPLES >"$work/man5-examples"
if "$py" -c 'import jsonschema, yaml' 2>/dev/null; then
    out=$("$py" - "$schema" "$pfx" "$work" "$src"/effects/*.yaml <<'PY'
import glob, json, os, subprocess, sys
import jsonschema, yaml

schema_path, pfx, tmp, effects = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]

# The harness's report lines (tests/harness.sh, tally).
def ok(msg): print("ok   " + msg)
def fail(msg, detail=""):
    print("FAIL " + msg)
    for line in detail.splitlines():
        print("    " + line)

try:
    with open(schema_path) as f:
        schema = json.load(f)
except Exception as e:
    fail("schemas/pfx-effect.schema.json is not JSON", str(e))
    sys.exit(0)
if schema.get("$schema") != "https://json-schema.org/draft/2020-12/schema":
    fail("the schema does not declare JSON Schema 2020-12 in $schema")
try:
    jsonschema.Draft202012Validator.check_schema(schema)
    ok("the schema is a valid JSON Schema 2020-12")
except jsonschema.exceptions.SchemaError as e:
    fail("the schema is not a valid JSON Schema 2020-12", str(e))
    sys.exit(0)
validator = jsonschema.Draft202012Validator(schema)

def schema_errors(text):
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as e:
        return ["not YAML: %s" % e]
    return ["%s: %s" % ("/".join(map(str, e.absolute_path)) or "(top)", e.message)
            for e in validator.iter_errors(doc)]

def pfx_validate(name, text):
    path = os.path.join(tmp, name + ".yaml")
    with open(path, "w") as f:
        f.write(text)
    r = subprocess.run([pfx, "validate", "-q", path], capture_output=True, text=True)
    return r.returncode, r.stderr

if not effects:
    fail("no effects/*.yaml to validate")
for path in effects:
    with open(path) as f:
        text = f.read()
    errs = schema_errors(text)
    name = "effects/" + os.path.basename(path)
    if errs:
        fail(name + " does not validate against the schema", "\n".join(errs))
    else:
        ok(name + " validates against the schema")

# Documents pfx accepts, written to reach the corners of the format.
good = {
    "minimal emitter": "pfx: 1\nemitters:\n  a: {}\n",
    "CSS colour names": "pfx: 1\nimage: { background: rebeccapurple }\nemitters:\n  a: { color: [red, orange, yellow] }\n",
    "allow a warning": "pfx: 1\nallow: { PFX5002: \"the splash counts differ\" }\nemitters:\n  a: {}\n",
    "every form": """\
pfx: 1.0
duration: 0.5
fps: 24
seed: 12345678901234567890
sim: { rate: 1, prewarm: 0 }
camera: { position: [1, 2, 3], target: [0, 0, 0], up: [0, 0, 1], ortho: 4 }
image: { size: [1, 16384], background: [0.1, 0.2, 0.3] }
forces:
  down: { type: gravity }
  wind: { type: gravity, accel: [1000000, 0, -1000000] }
emitters:
  a:
    shape: { type: box, size: [1, 0, 2] }
    rotation: [90, -45, 720]
    rate: 0
    direction: [0, 0, -2]
    spread: 180
    speed: { normal: [1, 0.5] }
    lifetime: { mean: 2 }
    size: { end: [0, 1000000] }
    color: ["#fff", "#ffff", "#ffffff", "#ffffff80", [1, 0, 0], [0, 1, 0, 0.5], transparent]
    forces: []
    gravity_scale: { normal: [0, 1], clamp: [-1000, 1000] }
    blend: alpha
  b:
    shape: { type: disc, radius: 0 }
    color: [{ at: 0, color: "#000" }, { at: 0.5, color: [1, 1, 1] }, { at: 0.5, color: "#f00" }]
    forces: [wind, down]
    size: { start: { mean: 1, var: 0.5 }, end: 0 }
  c:
    shape: { type: point }
    color: [[1, 0.5, 0], [1, 0, 0, 0]]
    lifetime: 86400
    rate: 10000000
""",
    "every shape, force and deflector": """\
pfx: 1
sim: { integrator: auto, tolerance: 0.0001, substeps: 2 }
forces:
  g: { type: gravity, region: { type: box, center: [0, 1, 0], size: [2, 2, 2], falloff: 0.5 } }
  well: { type: attractor, center: [0, 2, 0], strength: 2, softening: 0.2, falloff: constant, radius: 5, reference_radius: 0.5 }
  air: { type: drag, c: 0.1, wind: [1, 0, 0] }
  twist: { type: vortex, axis: [0, 0, 2], strength: -90, radius: 2, d: 1, inflow: 0.1 }
  b: { type: magnetic, field: [0, 0, 1], electric: [0, 10, 0], region: { type: sphere, radius: 3 } }
  sp: { type: spiral, center: [1, 0, 0], axis: [0, 1, 0], rate: 45 }
  s: { type: spring, anchor: [0, 1, 0], k: 4, zeta: 0.5 }
  s2: { type: spring, anchor: birth }
  t: { type: turbulence, strength: 1, scale: 0.5, octaves: 8, speed: 0.2 }
  lim: { type: speed_limit, max: 3 }
deflectors:
  ground: { type: plane }
  shelf: { type: plane, point: [0, 1, 0], normal: [0, 1, 1], size: [1, 2], response: stick }
  lid: { type: disc, point: [0, 3, 0], normal: [0, -1, 0], radius: 0.5, response: kill, chance: 0.5 }
  ball: { type: sphere, center: [1, 1, 0], radius: 0.3, resilience: [0.2, 0.6], friction: { mean: 0.3, var: 0.1 } }
  jar: { type: box, size: [4, 4, 4], inside: true, lifetime_loss: 0.1 }
emitters:
  a: { shape: { type: point, emit_from: volume }, integrator: rk4, charge: [-1, 1], mass: { normal: [1, 0.1], clamp: [0.5, 2] } }
  b: { shape: { type: line, from: [0, 0, 0], to: [1, 2, 3] }, forces: [], deflectors: [] }
  c: { shape: { type: rect, size: [1, 2], emit_from: edge }, direction: normal }
  d: { shape: { type: disc, radius: 1, inner: 0.5, arc: 90 }, direction: radial }
  e: { shape: { type: disc, radius: 1, emit_from: edge }, direction: inward }
  f: { shape: { type: ellipse, radii: [2, 1], emit_from: edge }, spread: [30, 60] }
  g: { shape: { type: box, size: [1, 1, 1], emit_from: surface }, distance: [0, 0.2] }
  h: { shape: { type: sphere, radius: 1, inner: 0.9 }, inherit_velocity: 0.5 }
  i: { shape: { type: hemisphere, radius: 1, emit_from: surface } }
  j: { shape: { type: cylinder, radius: 1, height: 2, emit_from: surface } }
  k: { shape: { type: cone, radius: 1, height: 2, angle: 30 }, deflectors: [ball, jar] }
""",
    "every emission, appearance, kill and sub-emitter form": """\
pfx: 1
duration: 4
forces:
  gravity: { type: gravity }
emitters:
  steady: { rate: { mean: 20, var: 5 }, start: 0.5, duration: 2 }
  ramp: { rate: { initial: 5, delta: 10 }, duration: 3, loop: true }
  curve:
    rate: [{ t: 0, value: 0 }, { t: 1, value: 50 }, { t: 2, value: 0 }]
    position: [{ t: 0, value: [0, 0, 0] }, { t: 4, value: [2, 0, 0] }]
    rotation: [{ t: 0, value: [0, 0, 0] }, { t: 4, value: [0, 360, 0] }]
    inherit_velocity: 1
  ticks:
    interval: { normal: [0.1, 0.02], clamp: [0.05, 0.2] }
    bursts:
      - { time: 0, count: 5 }
      - { time: 1, count: [10, 20], cycles: 3, interval: 0.5, probability: 0.5 }
    size: [{ at: 0, value: 0 }, { at: 0.5, value: 0.3 }, { at: 0.5, value: 0.2 }, { at: 1, value: 0 }]
    color: { random: ["#ff0000", [0, 0, 1, 0.5]] }
    alpha: { start: 1, end: 0 }
    kill:
      - inside: { box: { center: [0, 5, 0], size: [1, 1, 1] } }
      - outside: { sphere: { radius: 20 } }
      - inside: { half_space: { point: [0, -1, 0], normal: [0, -1, 0] } }
      - alpha_below: 0.05
      - distance_from_emitter: 10
    bounds: { box: { size: [30, 30, 30] } }
    on_birth: { emit: child, count: 1, probability: 0.5 }
    on_death: [{ emit: child, count: [1, 3], inherit: [velocity, color, size] }]
    on_hit: { emit: child }
    trail: { emit: child, rate: 20, inherit: [size], depth: 1 }
  child:
    color: { pick: ["#fff", "#f80", "#f00"] }
    alpha: [{ at: 0, value: 1 }, { at: 1, value: 0 }]
    bounds: { box: { center: [0, 1, 0], size: [4, 4, 4] }, mode: wrap }
    on_death: { emit: child, depth: 2 }
  far: { lod: { per_pixel: 0.01, var: 0.005 }, shape: { type: sphere, radius: 0.5 } }
""",
    "a seamless loop": """\
pfx: 1
duration: 2
fps: 25
loop: true
emitters:
  a: { rate: 30, alpha: 0.5 }
  b: { bursts: [{ time: 0.5, count: 20, cycles: 2, interval: 1 }], loop: true, duration: 1 }
""",
}
# Documents pfx rejects; the schema must reject each of them too.
bad = {
    "unknown top-level key": "pfx: 1\ndurration: 3\n",
    "misspelt colour name": "pfx: 1\nemitters:\n  a: { color: oragne }\n",
    "allow an error rule": "pfx: 1\nallow: { PFX3001: \"no\" }\nemitters:\n  a: {}\n",
    "allow with an empty reason": "pfx: 1\nallow: { PFX5002: \"\" }\nemitters:\n  a: {}\n",
    "unknown emitter key": "pfx: 1\nemitters:\n  a: { colr: \"#fff\", no_such_key: 1 }\n",
    "unknown shape type": "pfx: 1\nemitters:\n  a: { shape: { type: cube } }\n",
    "shape with another type's key": "pfx: 1\nemitters:\n  a: { shape: { type: sphere, size: [1, 1, 1] } }\n",
    "sphere without radius": "pfx: 1\nemitters:\n  a: { shape: { type: sphere } }\n",
    "point with a radius": "pfx: 1\nemitters:\n  a: { shape: { type: point, radius: 1 } }\n",
    "unknown force type": "pfx: 1\nforces:\n  g: { type: no_such_force }\n",
    "unknown gravity key": "pfx: 1\nforces:\n  g: { type: gravity, accell: [0, 1, 0] }\n",
    "force without type": "pfx: 1\nforces:\n  g: { accel: [0, 1, 0] }\n",
    "missing pfx": "duration: 1\n",
    "wrong version": "pfx: 2\n",
    "unknown sim key": "pfx: 1\nsim: { rate: 60, no_such_key: 2 }\n",
    "unknown camera key": "pfx: 1\ncamera: { no_such_key: 2 }\n",
    "fov and ortho": "pfx: 1\ncamera: { fov: 40, ortho: 4 }\n",
    "fov 180": "pfx: 1\ncamera: { fov: 180 }\n",
    "image size 0": "pfx: 1\nimage: { size: [0, 512] }\n",
    "image size too big": "pfx: 1\nimage: { size: [16385, 512] }\n",
    "malformed colour": "pfx: 1\nimage: { background: \"#12345\" }\n",
    "colour above 1": "pfx: 1\nimage: { background: [1, 2, 0] }\n",
    "negative rate": "pfx: 1\nemitters:\n  a: { rate: -3 }\n",
    "zero lifetime": "pfx: 1\nemitters:\n  a: { lifetime: 0 }\n",
    "negative var": "pfx: 1\nemitters:\n  a: { lifetime: { mean: 1, var: -1 } }\n",
    "mean with normal": "pfx: 1\nemitters:\n  a: { speed: { mean: 1, normal: [1, 0.1] } }\n",
    "range of three": "pfx: 1\nemitters:\n  a: { speed: [1, 2, 3] }\n",
    "negative size range": "pfx: 1\nemitters:\n  a: { size: [-1, 2] }\n",
    "unknown size key": "pfx: 1\nemitters:\n  a: { size: { start: 1, middle: 2 } }\n",
    "zero direction": "pfx: 1\nemitters:\n  a: { direction: [0, 0, 0] }\n",
    "spread above 180": "pfx: 1\nemitters:\n  a: { spread: 181 }\n",
    "unknown blend": "pfx: 1\nemitters:\n  a: { blend: multiply }\n",
    "unknown stop key": "pfx: 1\nemitters:\n  a: { color: [{ at: 0, color: \"#fff\", alpha: 1 }] }\n",
    "empty gradient": "pfx: 1\nemitters:\n  a: { color: [] }\n",
    "gravity_scale too big": "pfx: 1\nemitters:\n  a: { gravity_scale: 1001 }\n",
    "emitter not a mapping": "pfx: 1\nemitters:\n  a: 3\n",
    "rate and interval": "pfx: 1\nemitters:\n  a: { rate: 3, interval: 0.1 }\n",
    "lod and rate": "pfx: 1\nemitters:\n  a: { rate: 3, lod: { per_pixel: 1 } }\n",
    "empty rate mapping": "pfx: 1\nemitters:\n  a: { rate: {} }\n",
    "loop without duration": "pfx: 1\nemitters:\n  a: { loop: true }\n",
    "loop not a boolean": "pfx: 1\nloop: 1\n",
    "burst cycles without interval": "pfx: 1\nemitters:\n  a: { bursts: [{ time: 0, cycles: 3 }] }\n",
    "burst probability above 1": "pfx: 1\nemitters:\n  a: { bursts: [{ probability: 1.5 }] }\n",
    "inner on a surface": "pfx: 1\nemitters:\n  a: { shape: { type: sphere, radius: 1, inner: 0.5, emit_from: surface } }\n",
    "emit_from the shape lacks": "pfx: 1\nemitters:\n  a: { shape: { type: point, emit_from: surface } }\n",
    "mesh by volume": "pfx: 1\nemitters:\n  a: { shape: { type: mesh, file: no.obj, emit_from: volume } }\n",
    "cone angle above 90": "pfx: 1\nemitters:\n  a: { shape: { type: cone, radius: 1, height: 1, angle: 91 } }\n",
    "unknown direction word": "pfx: 1\nemitters:\n  a: { direction: outward }\n",
    "two-angle spread above 360": "pfx: 1\nemitters:\n  a: { spread: [10, 400] }\n",
    "zero mass": "pfx: 1\nemitters:\n  a: { mass: 0 }\n",
    "alpha above 1": "pfx: 1\nemitters:\n  a: { alpha: 1.5 }\n",
    "size curve past death": "pfx: 1\nemitters:\n  a: { size: [{ at: 1.5, value: 1 }] }\n",
    "unknown colour mapping": "pfx: 1\nemitters:\n  a: { color: { mix: [\"#fff\", \"#000\"] } }\n",
    "unknown integrator": "pfx: 1\nsim: { integrator: leapfrog }\n",
    "too many substeps": "pfx: 1\nsim: { substeps: 1025 }\n",
    "fractional substeps": "pfx: 1\nsim: { substeps: 1.5 }\n",
    "zero tolerance": "pfx: 1\nsim: { tolerance: 0 }\n",
    "turbulence octaves 9": "pfx: 1\nforces:\n  t: { type: turbulence, octaves: 9 }\n",
    "spring anchor word": "pfx: 1\nforces:\n  s: { type: spring, anchor: origin }\n",
    "vortex zero axis": "pfx: 1\nforces:\n  v: { type: vortex, axis: [0, 0, 0] }\n",
    "attractor unknown falloff": "pfx: 1\nforces:\n  a: { type: attractor, falloff: cubic }\n",
    "drag key of another force": "pfx: 1\nforces:\n  d: { type: drag, strength: 1 }\n",
    "unknown region type": "pfx: 1\nforces:\n  g: { type: gravity, region: { type: cylinder } }\n",
    "unknown deflector type": "pfx: 1\ndeflectors:\n  d: { type: cube }\n",
    "sphere deflector with a normal": "pfx: 1\ndeflectors:\n  d: { type: sphere, normal: [0, 1, 0] }\n",
    "resilience above 1": "pfx: 1\ndeflectors:\n  d: { type: plane, resilience: [0.5, 1.5] }\n",
    "unknown response": "pfx: 1\ndeflectors:\n  d: { type: plane, response: slide }\n",
    "kill rule with two keys": "pfx: 1\nemitters:\n  a: { kill: [{ alpha_below: 0.1, distance_from_emitter: 3 }] }\n",
    "kill sphere without radius": "pfx: 1\nemitters:\n  a: { kill: [{ inside: { sphere: { center: [0, 0, 0] } } }] }\n",
    "wrapping box with a zero edge": "pfx: 1\nemitters:\n  a: { bounds: { box: { size: [1, 0, 1] }, mode: wrap } }\n",
    "bounds without box": "pfx: 1\nemitters:\n  a: { bounds: { mode: kill } }\n",
    "sub-emitter without emit": "pfx: 1\nemitters:\n  a: { on_death: { count: 3 } }\n",
    "trail with a count": "pfx: 1\nemitters:\n  a: { trail: { emit: b, count: 2 } }\n  b: {}\n",
    "depth 17": "pfx: 1\nemitters:\n  a: { on_death: { emit: b, depth: 17 } }\n  b: {}\n",
    "unknown inherited attribute": "pfx: 1\nemitters:\n  a: { on_death: { emit: b, inherit: [spin] } }\n  b: {}\n",
}

# What pfx must say about each bad document: its own error, not another
# one (a document rejected for the wrong reason shows nothing about the
# rule it was written for). Each is part of an `error:` line.
reason = {
    "unknown top-level key": "unknown key 'durration' in the effect",
    "misspelt colour name": "unknown colour 'oragne' in 'color'; did you mean 'orange'?",
    "allow an error rule": "PFX3001 (out-of-range) is an error, which 'allow' cannot acknowledge",
    "allow with an empty reason": "the reason for allowing PFX5002 is empty",
    "unknown emitter key": "unknown key 'no_such_key' in emitter 'a'",
    "unknown shape type": "unknown shape type 'cube'",
    "shape with another type's key": "unknown key 'size' in the shape of emitter 'a'",
    "sphere without radius": "a sphere shape needs a 'radius'",
    "point with a radius": "unknown key 'radius' in the shape of emitter 'a'",
    "unknown force type": "unknown force type 'no_such_force'",
    "unknown gravity key": "unknown key 'accell' in force 'g'",
    "force without type": "force 'g' needs a 'type'",
    "missing pfx": "missing 'pfx: 1'",
    "wrong version": "unsupported format version '2'",
    "unknown sim key": "unknown key 'no_such_key' in 'sim'",
    "unknown camera key": "unknown key 'no_such_key' in 'camera'",
    "fov and ortho": "'camera' takes either 'fov' or 'ortho', not both",
    "fov 180": "'fov' must be between 0 and 180 degrees (exclusive), got 180",
    "image size 0": "image 'size' must be whole numbers of pixels from 1 to 16384, got 0",
    "image size too big": "image 'size' must be whole numbers of pixels from 1 to 16384, got 16385",
    "malformed colour": "malformed colour '#12345' in 'background'",
    "colour above 1": "colour components of 'background' must be in 0..1, got 2",
    "negative rate": "'rate' must be at least 0, got -3",
    "zero lifetime": "'lifetime' must be greater than 0, got 0",
    "negative var": "'var' of 'lifetime' must be at least 0, got -1",
    "mean with normal": "'speed' must be a number, [min, max], {mean: m, var: v} or {normal:",
    "range of three": "'speed' as a list must be [min, max]",
    "negative size range": "'size' must be at least 0, got -1",
    "unknown size key": "unknown key 'middle' in 'size'",
    "zero direction": "'direction' must not be the zero vector",
    "spread above 180": "'spread' must be at most 180, got 181",
    "unknown blend": "unknown blend mode 'multiply'",
    "unknown stop key": "unknown key 'alpha' in a gradient stop",
    "empty gradient": "gradient 'color' needs at least one colour",
    "gravity_scale too big": "'gravity_scale' must be at most 1000, got 1001",
    "emitter not a mapping": "'a' must be a mapping, got a scalar",
    "rate and interval": "an emitter takes either 'rate' or 'interval', not both",
    "lod and rate": "'lod' sets the rate from the screen area; drop 'rate'",
    "empty rate mapping": "'rate' must be a number, {mean, var}, {initial, delta} or a curve",
    "loop without duration": "a looping emitter needs a 'duration'",
    "loop not a boolean": "'loop' must be true or false",
    "burst cycles without interval": "a burst with 'cycles' above 1 needs an 'interval' above 0",
    "burst probability above 1": "'probability' must be at most 1, got 1.5",
    "inner on a surface": "'inner' applies only to emit_from: volume",
    "emit_from the shape lacks": "a point shape cannot emit from 'surface'",
    "mesh by volume": "a mesh shape cannot emit from 'volume'",
    "cone angle above 90": "'angle' must be at most 90, got 91",
    "unknown direction word": "unknown direction 'outward'",
    "two-angle spread above 360": "'spread' must be at most 360, got 400",
    "zero mass": "'mass' must be greater than 0, got 0",
    "alpha above 1": "'alpha' must be at most 1, got 1.5",
    "size curve past death": "'at' must be in 0..1, got 1.5",
    "unknown colour mapping": "unknown key 'mix' in 'color'",
    "unknown integrator": "unknown integrator 'leapfrog'",
    "too many substeps": "'substeps' must be at most 1024, got 1025",
    "fractional substeps": "'substeps' must be a whole number, got 1.5",
    "zero tolerance": "'tolerance' must be at least 1e-12, got 0",
    "turbulence octaves 9": "'octaves' must be at most 8, got 9",
    "spring anchor word": "'anchor' must be a point [x, y, z] or 'birth'",
    "vortex zero axis": "'axis' must not be the zero vector",
    "attractor unknown falloff": "unknown falloff 'cubic'",
    "drag key of another force": "unknown key 'strength' in force 'd'",
    "unknown region type": "unknown region type 'cylinder'",
    "unknown deflector type": "unknown deflector type 'cube'",
    "sphere deflector with a normal": "unknown key 'normal' in deflector 'd'",
    "resilience above 1": "'resilience' must be at most 1, got 1.5",
    "unknown response": "unknown response 'slide'",
    "kill rule with two keys": "a kill rule has one key",
    "kill sphere without radius": "a sphere needs a 'radius'",
    "wrapping box with a zero edge": "a wrapping box's 'size' must be greater than 0, got 0",
    "bounds without box": "'bounds' needs a 'box'",
    "sub-emitter without emit": "a sub-emitter needs 'emit: <emitter name>'",
    "trail with a count": "unknown key 'count' in a trail",
    "depth 17": "'depth' must be at most 16, got 17",
    "unknown inherited attribute": "unknown inherited attribute 'spin'",
}

for name, text in good.items():
    errs = schema_errors(text)
    rc, err = pfx_validate("good", text)
    if errs:
        fail("the schema rejects a good document (%s)" % name, "\n".join(errs))
    elif rc != 0:
        fail("pfx validate rejects the good test document (%s)" % name, err)
    else:
        ok("schema and pfx both accept: " + name)
for name, text in bad.items():
    errs = schema_errors(text)
    rc, err = pfx_validate("bad", text)
    said = [line for line in err.splitlines() if ": error: " in line and reason[name] in line]
    if rc != 1:
        fail("pfx validate exits %d, not 1, on the bad test document (%s)" % (rc, name), err)
    elif not said:
        fail("pfx validate rejects the bad test document (%s) without the error '%s'"
             % (name, reason[name]), err)
    elif not errs:
        fail("the schema accepts a bad document (%s)" % name, text)
    else:
        ok("schema and pfx both reject: " + name)

# The annotated examples of pfx-effect.5.
with open(os.path.join(tmp, "man5-examples")) as f:
    blocks = [b.strip("\n") + "\n" for b in f.read().split("@@END@@\n") if b.strip()]
if not blocks:
    fail("no examples found in the EXAMPLES section of man/pfx-effect.5")
for i, text in enumerate(blocks, 1):
    errs = schema_errors(text)
    rc, err = pfx_validate("man-example-%d" % i, text)
    if errs:
        fail("example %d of pfx-effect.5 does not validate against the schema" % i, "\n".join(errs))
    elif rc != 0 or err:
        fail("pfx validate does not accept example %d of pfx-effect.5 cleanly" % i, err)
    else:
        ok("example %d of pfx-effect.5 is valid for pfx and the schema" % i)
PY
)
    tally "$out"
else
    fail "$py cannot import jsonschema and yaml (apt-get install python3-jsonschema python3-yaml)"
fi

# --- (e) every key and name of the key tables is described in pfx-effect.5 -
# "<table> <name>" for every property of every table and every name of every
# enum, read from `pfx schema` (which the key tables generate): a key added
# there without docs fails here. top_keys and emitter_keys are the top
# level's and an emitter's keys.
string_arrays() {
    "$pfx" schema | "$py" -c '
import json, sys
s = json.load(sys.stdin)
def walk(table, node):
    if isinstance(node, dict):
        for k, v in node.get("properties", {}).items():
            print(table, k)
            walk(table.replace("_keys", "") + "_nested", v)
        for e in node.get("enum", []):
            if isinstance(e, str):
                print(table + "_names", e)
        for k, v in node.items():
            if k != "properties":
                walk(table, v)
    elif isinstance(node, list):
        for v in node:
            walk(table, v)
for k, v in s.get("properties", {}).items():
    print("top_keys", k)
    walk("top", v)
for name, d in s["$defs"].items():
    walk("emitter_keys" if name == "emitter" else name, d)
'
}
arrays=$(string_arrays)
# Bold text of the page: \fB...\fR runs, .B lines, first words of .BR/.BI.
bold=$(
    sed -e 's/\\-/-/g' "$man5" | grep -oE '\\fB([^\\]|\\[^f])*' | sed 's/^\\fB//'
    sed -e 's/\\-/-/g' "$man5" | sed -n 's/^\.B //p'
    sed -e 's/\\-/-/g' "$man5" | sed -nE 's/^\.(BR|BI) +"?([^" ]*).*/\2/p'
)
# Tags (the bold first word after .TP) per section: "<section>\t<tag>".
tags=$(sed -e 's/\\-/-/g' "$man5" | awk '
    /^\.SH / { sec = substr($0, 5); gsub(/"/, "", sec); next }
    prev == ".TP" {
        t = ""
        if (match($0, /^\\fB[a-z_]+\\f[RP]/)) t = substr($0, 4, RLENGTH - 6)
        else if ($0 ~ /^\.B [a-z_]+$/) t = substr($0, 4)
        if (t != "") print sec "\t" t
    }
    { prev = $0 }
')
for want in top_keys emitter_keys; do
    if ! printf '%s\n' "$arrays" | grep -q "^$want "; then
        fail "pfx schema lists no $want"
    fi
done
undescribed=""
untagged=""
count=0
while read -r array key; do
    [ -n "$key" ] || continue
    count=$((count + 1))
    if ! printf '%s\n' "$bold" | grep -qw -- "$key"; then
        undescribed="$undescribed $key ($array)"
    fi
    section=""
    case $array in
    top_keys) section=$top_section ;;
    emitter_keys) section=$emitter_section ;;
    esac
    if [ -n "$section" ] && ! printf '%s\n' "$tags" | grep -qxF "$section	$key"; then
        untagged="$untagged $key"
    fi
done <<<"$arrays"
if [ -n "$undescribed" ]; then
    fail "keys and names accepted by the compiler or listed by the schema but not described (in bold) in man/pfx-effect.5:$undescribed"
else
    pass "all $count keys and names of the compiler's string arrays and the schema are described in man/pfx-effect.5"
fi
if [ -n "$untagged" ]; then
    fail "top-level or emitter keys without their own paragraph in sections '$top_section' or '$emitter_section' of man/pfx-effect.5:$untagged"
else
    pass "every top-level and emitter key has its own paragraph in man/pfx-effect.5"
fi

# --- (f) the diagnostics example of pfx.1 is what pfx prints --------------
examples_of "$man1" DIAGNOSTICS >"$work/man1-diag"
nth_block "$work/man1-diag" 1 >"$work/flame.yaml"
nth_block "$work/man1-diag" 2 >"$work/flame.expected"
if [ ! -s "$work/flame.yaml" ] || [ ! -s "$work/flame.expected" ]; then
    fail "could not find the example file and its diagnostics in DIAGNOSTICS of man/pfx.1"
else
    (cd "$work" && "$pfx" validate flame.yaml) >"$work/flame.stdout" 2>"$work/flame.actual"
    rc=$?
    if [ $rc -eq 1 ] && [ ! -s "$work/flame.stdout" ] && cmp -s "$work/flame.expected" "$work/flame.actual"; then
        pass "the diagnostics shown in man/pfx.1 are what pfx validate prints"
    else
        fail "pfx validate on the example of man/pfx.1 (status $rc) differs from the page" \
            "$(diff "$work/flame.expected" "$work/flame.actual")"
    fi
fi

summary
