#!/usr/bin/env bash
# --motion-vectors: known displacements read back by a decoder of our own
# (check_motion_vectors.py: the camera formula, the encoding, the sign of
# each axis, averaging under overlap, additive weights); the same bytes for
# --threads 1 and 7, -j 2 and a --frames range; the sheet in the colour
# atlas's cells; the manifest; the usage errors.
#
#   bash run_motion_vectors.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" motion_vectors "$@"
cd "$work" || exit 2
mkdir known
tally "$("$py" "$src/tests/jobs/check_motion_vectors.py" "$pfx" "$work/known" "$src" 2>&1)"

FIRE=$src/effects/fire.yaml
A=(--size 48x40 --seed 4 -q --motion-vectors)

begin "the same motion-vector bytes for --threads 1 and 7, -j 2 and --frames 20:23"
pfx_run render "$FIRE" -o t1 "${A[@]}" --frames 10:25 --threads 1
want_status 0
pfx_run render "$FIRE" -o t7 "${A[@]}" --frames 10:25 --threads 7
want_status 0
pfx_run render "$FIRE" -o j2 "${A[@]}" --frames 10:25 -j 2
want_status 0
pfx_run render "$FIRE" -o part "${A[@]}" --frames 20:23
want_status 0
n=0
for f in t1/fire_mv_*.png; do
    name=${f#t1/}
    n=$((n + 1))
    cmp -s "$f" "t7/$name" || flunk "$name differs with 7 threads"
    cmp -s "$f" "j2/$name" || flunk "$name differs with -j 2"
done
[ "$n" = 16 ] || flunk "$n motion-vector frames, expected 16"
for k in 20 21 22 23; do
    cmp -s "t1/fire_mv_00$k.png" "part/fire_mv_00$k.png" || flunk "fire_mv_00$k.png differs in --frames 20:23"
done
cmp -s t1/fire_mv.json part/fire_mv.json 2>/dev/null ||
    "$py" -c 'import json,sys; a,b=(json.load(open(p))["motion_vectors"]["max_px"] for p in sys.argv[1:]); sys.exit(a!=b)' \
        t1/fire_mv.json part/fire_mv.json || flunk "the ranges chose different scales"
grep -q '"fire_mv_0010.png"' t1/fire.manifest.json && grep -q '"fire_mv.json"' t1/fire.manifest.json ||
    flunk "the manifest does not list the motion vectors"
end

begin "the motion-vector sheet lines up with the colour atlas (--crop --padding 3)"
pfx_run render "$FIRE" -o at "${A[@]}" --frames 10:20 --atlas --crop --padding 3 --extrude 2
want_status 0
[ -f at/fire_mv_atlas.png ] || flunk "no fire_mv_atlas.png"
[ ! -e at/fire_mv.json ] || flunk "a sidecar beside the atlas JSON"
grep -q '"fire_mv_atlas.png"' at/fire.manifest.json || flunk "the manifest does not list the sheet"
report=$("$py" - "$src" <<'PY'
import json, sys
import numpy as np
from PIL import Image
sys.path.insert(0, sys.argv[1] + "/tests")
import png16
meta = json.load(open("at/fire_atlas.json"))
mv = meta["motion_vectors"]
sheet = png16.decode("at/" + mv["image"])
colour = Image.open("at/fire_atlas.png")
bad = []
if sheet.shape[:2] != (colour.size[1], colour.size[0]):
    bad.append("sheet %s, colour atlas %s" % (sheet.shape[:2], colour.size))
if not (mv["max_px"] > 0 and mv["r"].startswith("+x: right") and mv["g"].startswith("+y: up")):
    bad.append("encoding %s" % mv)
g, pad = meta["grid"], meta["grid"]["padding"]
cw, ch = g["cell"]["w"], g["cell"]["h"]
if abs(mv["strength_cell"]["x"] - mv["max_px"] / cw) > 1e-12:
    bad.append("strength %s" % mv["strength_cell"])
for k, name in enumerate(meta["frames"]):
    fr = meta["frames"][name]
    r, s = fr["frame"], fr["spriteSourceSize"]
    frame = png16.decode("at/" + name.replace("fire_", "fire_mv_"))
    want = frame[s["y"]:s["y"] + s["h"], s["x"]:s["x"] + s["w"]]
    got = sheet[r["y"]:r["y"] + r["h"], r["x"]:r["x"] + r["w"]]
    if not np.array_equal(got, want):
        bad.append("%s: its rectangle is not the motion-vector frame" % name)
    cx, cy = (k % g["columns"]) * cw, (k // g["columns"]) * ch
    cell = sheet[cy:cy + ch, cx:cx + cw]
    e = min(g["extrude"], pad)
    gutter = np.ones(cell.shape[:2], bool)
    gutter[pad - e:pad + r["h"] + e, pad - e:pad + r["w"] + e] = False
    if not (cell[gutter] == [32768, 32768, 0, 0]).all():
        bad.append("%s: the gutter is not (0.5, 0.5, 0, 0)" % name)
print(("FAIL motion-vector sheet: " + "; ".join(bad)) if bad else
      "ok   motion-vector sheet: %d cells equal to their frames, gutters neutral" % len(meta["frames"]))
PY
)
case $report in ok*) ;; *) flunk "$report" ;; esac
end

begin "a render without --motion-vectors removes the old ones"
pfx_run render "$FIRE" -o part --size 48x40 --seed 4 -q --frames 20:23
want_status 0
[ -z "$(ls part | grep _mv)" ] || flunk "left: $(ls part | grep _mv | head -3)"
end

begin "--mv-max without --motion-vectors is a usage error"
pfx_run render "$FIRE" -o u --mv-max 3
want_status 2
stderr_has "--mv-max and --mv-flip-y go with --motion-vectors"
end

begin "--mv-max 0 is a usage error"
pfx_run render "$FIRE" -o u --motion-vectors --mv-max 0
want_status 2
stderr_has "--mv-max takes pixels in (0, 1000000], got '0'"
end

begin "--motion-vectors with --slice is a usage error"
pfx_run render "$FIRE" -o u --motion-vectors --slice 0/2
want_status 2
stderr_has "--motion-vectors does not work with --slice yet"
end

summary
