#!/usr/bin/env bash
# pfx bake's formats, read back by readers pfx has no part in: the CSV by
# Python's csv module, the PLY by meshio (Debian's python3-meshio), the
# pcache by meshio too once its header is rewritten as the PLY header it
# mirrors (same types, same little-endian records), and checked line by line
# against Unity's pcache header grammar. Every particle of every format must
# equal the CSV's row, float for float. `-o -` writes to standard output and
# no file named '-'.
#
#   bash run_bake_formats.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" bake_formats "$@"
cd "$work" || exit 2
FIRE=$src/effects/fire.yaml
R=(--frames 10:14 --seed 3)

begin "bake csv, ply and pcache"
for f in csv ply pcache; do
    pfx_run bake "$FIRE" -o "$work/fire.$f" "${R[@]}" -q
    finished "$f" && want_status 0
    [ -s "$work/fire.$f" ] || flunk "no fire.$f"
done
end

begin "--format wins over the extension"
pfx_run bake "$FIRE" -o "$work/cache.bin" --format ply "${R[@]}" -q
want_status 0
cmp -s "$work/cache.bin" "$work/fire.ply" || flunk "--format ply differs from fire.ply"
end

out=$("$py" - "$work" <<'PY'
import csv, sys
import numpy as np
import meshio

d = sys.argv[1]
def ok(m): print("ok   " + m)
def fail(m): print("FAIL " + m)

rows = list(csv.DictReader(open(d + "/fire.csv")))
if not rows:
    fail("the CSV has no rows"); sys.exit()
f32 = lambda k: np.array([float(r[k]) for r in rows], dtype=np.float32)
want = {
    "frame": np.array([int(r["frame"]) for r in rows]),
    "id": np.array([int(r["id"]) for r in rows]),
    "x": f32("x"), "y": f32("y"), "z": f32("z"),
    "vx": f32("vx"), "vy": f32("vy"), "vz": f32("vz"),
    "red": f32("r"), "green": f32("g"), "blue": f32("b"), "alpha": f32("a"),
    "size": f32("size"), "age": f32("age"), "lifetime": f32("lifetime"),
}
names = [r["emitter"] for r in rows]

def check(label, mesh, emitters):
    got = dict(mesh.point_data)
    got["x"], got["y"], got["z"] = (mesh.points[:, i].astype(np.float32) for i in range(3))
    n = len(mesh.points)
    if n != len(rows):
        fail("%s holds %d particles, the CSV %d" % (label, n, len(rows))); return
    # age is a double in the simulation: the CSV prints it to 9 digits, the
    # binary formats round it to a float, so the two agree to a float's
    # precision rather than bit for bit. Every other column is a float or an
    # integer in the simulation and must match exactly.
    bad = [k for k, v in want.items() if k != "age" and
           not np.array_equal(np.asarray(got[k]).astype(v.dtype), v)]
    if not np.allclose(got["age"], want["age"], rtol=2e-7, atol=1e-9):
        bad.append("age")
    em = [emitters[int(i)] for i in got["emitter"]]
    if em != names:
        bad.append("emitter")
    if bad:
        fail("%s differs from the CSV in %s" % (label, ", ".join(bad)))
    else:
        ok("%s: %d particles equal the CSV's, every column" % (label, n))

def emitters_of(header):
    return [l.split(" ", 3)[3] for l in header if l.startswith("comment emitter ")]

ply = open(d + "/fire.ply", "rb").read()
head = ply[:ply.index(b"end_header\n")].decode().splitlines()
if head[:2] != ["ply", "format binary_little_endian 1.0"]:
    fail("the PLY does not start as binary little-endian PLY: %r" % head[:2])
check("PLY through meshio", meshio.read(d + "/fire.ply"), emitters_of(head))

pc = open(d + "/fire.pcache", "rb").read()
end = pc.index(b"end_header\n") + len(b"end_header\n")
lines = pc[:end].decode().splitlines()
# Unity's grammar: pcache, format binary 1.0, comments, elements N,
# property (float|int|uchar) NAME..., end_header.
problems = []
if lines[:2] != ["pcache", "format binary 1.0"]:
    problems.append("starts %r" % lines[:2])
props = [l.split() for l in lines if l.startswith("property ")]
if any(len(p) != 3 or p[1] not in ("float", "int", "uchar") for p in props):
    problems.append("a property of a type Unity does not read")
for attr in ("position.x", "position.y", "position.z", "velocity.x", "color.r", "color.a", "size", "age", "id"):
    if attr not in [p[2] for p in props]:
        problems.append("no %s" % attr)
count = [int(l.split()[1]) for l in lines if l.startswith("elements ")]
if count != [len(rows)]:
    problems.append("elements %s, expected %d" % (count, len(rows)))
if len(pc) - end != len(rows) * 4 * len(props):
    problems.append("%d bytes after the header, expected %d" % (len(pc) - end, len(rows) * 4 * len(props)))
if problems:
    fail("the pcache header: " + "; ".join(problems))
else:
    ok("the pcache header follows Unity's grammar, %d properties" % len(props))
# The same records under the PLY header they mirror.
ply_names = {"position.x": "x", "position.y": "y", "position.z": "z", "velocity.x": "vx",
             "velocity.y": "vy", "velocity.z": "vz", "color.r": "red", "color.g": "green",
             "color.b": "blue", "color.a": "alpha"}
as_ply = ["ply", "format binary_little_endian 1.0", "element vertex %d" % len(rows)]
as_ply += ["property %s %s" % (t, ply_names.get(n, n)) for _, t, n in props]
as_ply += ["end_header", ""]
open(d + "/pcache-as.ply", "wb").write("\n".join(as_ply).encode() + pc[end:])
check("pcache records through meshio", meshio.read(d + "/pcache-as.ply"), emitters_of(lines))
PY
)
tally "$out"

# -o -: the same bytes on standard output, and no file named '-'.
for f in csv ply pcache; do
    begin "bake -o - --format $f is the file's bytes on stdout"
    mkdir -p "$work/stdout-$f" && cd "$work/stdout-$f" || exit 2
    pfx_run bake "$FIRE" -o - --format "$f" "${R[@]}" -q
    want_status 0
    cmp -s "$work/out" "$work/fire.$f" || flunk "stdout differs from fire.$f"
    [ -z "$(ls -A)" ] || flunk "files were written: $(ls -A)"
    cd "$work" || exit 2
    end
done

begin "bake -o - keeps the summary on stderr"
pfx_run bake "$FIRE" -o - "${R[@]}"
want_status 0
stderr_has "to 'standard output'"
[ "$(head -1 "$work/out")" = "frame,time,emitter,id,x,y,z,vx,vy,vz,age,lifetime,size,r,g,b,a" ] ||
    flunk "stdout does not start with the CSV header"
end

begin "bake --format xyz is a usage error"
pfx_run bake "$FIRE" -o "$work/x.xyz" --format xyz
want_status 2
stderr_has "bake --format takes 'csv', 'ply' or 'pcache', got 'xyz'"
[ ! -e "$work/x.xyz" ] || flunk "a file was written"
end

summary
