#!/usr/bin/env bash
# --motion-vectors: known displacements read back by a decoder of our own
# (check_motion_vectors.py: the camera formula, the encoding, the sign of
# each axis, averaging under overlap, additive weights, a vortex, a death
# between frames, the percentile scale, motion_vectors: false); the same
# bytes for --threads 1 and 7, -j 1, 2 and 3 and a --frames range (fire,
# and the tornado, which a vortex moves); the sheet in the colour atlas's cells; the manifest; the
# usage errors; three slices assembled (with and without --atlas) equal to
# a one-process render, file for file; the pass's memory in --max-memory.
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

# The vortex moves the tornado's dust: its ends come from a simulation one
# frame ahead, which must not depend on the frames a job renders.
begin "a vortex's motion vectors: the same bytes for -j 1, -j 3 and --frames 20:23"
TORNADO=$src/effects/tornado.yaml
pfx_run render "$TORNADO" -o v1 "${A[@]}" --frames 10:25 -j 1
want_status 0
pfx_run render "$TORNADO" -o v3 "${A[@]}" --frames 10:25 -j 3
want_status 0
pfx_run render "$TORNADO" -o vpart "${A[@]}" --frames 20:23
want_status 0
n=0
for f in v1/tornado_mv_*.png; do
    n=$((n + 1))
    cmp -s "$f" "v3/${f#v1/}" || flunk "${f#v1/} differs with -j 3"
done
[ "$n" = 16 ] || flunk "$n motion-vector frames, expected 16"
for k in 20 21 22 23; do
    cmp -s "v1/tornado_mv_00$k.png" "vpart/tornado_mv_00$k.png" ||
        flunk "tornado_mv_00$k.png differs in --frames 20:23"
done
cmp -s v1/tornado_mv.json v3/tornado_mv.json || flunk "the sidecars differ with -j 3"
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

# Slices: each writes its motion-vector frames and records the scale; the
# assembly must equal a one-process render file for file, byte for byte.
key() { "$py" -c 'import json,sys; print(json.load(open(sys.argv[1]))["bake_key"])' "$1"; }
# outputs MANIFEST: its outputs, path and hash, sorted.
outputs() { "$py" -c 'import json,sys; [print(o["path"], o["sha256"]) for o in sorted(json.load(open(sys.argv[1]))["outputs"], key=lambda o: o["path"])]' "$1"; }
# same_render ONE ALL: the same files but the manifest byte for byte, and
# manifests with the same key and outputs.
same_render() {
    local f
    [ "$(ls "$1")" = "$(ls "$2")" ] || flunk "$2 holds $(ls "$2" | tr '\n' ' '), $1 $(ls "$1" | tr '\n' ' ')"
    for f in "$1"/*; do
        case $f in *.manifest.json) continue ;; esac
        cmp -s "$f" "$2/${f#"$1"/}" || flunk "$2/${f#"$1"/} differs from the one-process file"
    done
    [ "$(key "$1/fire.manifest.json")" = "$(key "$2/fire.manifest.json")" ] || flunk "the bake keys differ"
    [ "$(outputs "$1/fire.manifest.json")" = "$(outputs "$2/fire.manifest.json")" ] || flunk "the manifests list other outputs"
}
S=(--size 48x40 --seed 4 -q --frames 10:20 --motion-vectors)

begin "three slices with --motion-vectors in one directory, assembled: a one-process render"
pfx_run render "$FIRE" -o mv-one "${S[@]}"
want_status 0
for i in 0 1 2; do
    pfx_run render "$FIRE" -o mv-s "${S[@]}" --slice $i/3
    want_status 0
done
[ ! -e mv-s/fire_mv.json ] || flunk "a slice wrote the sidecar of the whole"
# 11 frames: every slice lists its own colour and motion-vector frames, and
# all three found the one scale of the whole effect.
n=$("$py" -c 'import json,sys; print(sum(o["path"].startswith("fire_mv_") for p in sys.argv[1:] for o in json.load(open(p))["outputs"]))' mv-s/fire.slice-*.manifest.json)
[ "$n" = 11 ] || flunk "the slice manifests list $n motion-vector frames, not 11"
scales=$("$py" -c 'import json,sys; print(" ".join(repr(json.load(open(p))["slice"]["mv_max_px"]) for p in sys.argv[1:]))' mv-s/fire.slice-*.manifest.json)
one=$("$py" -c 'import json,sys; print(repr(json.load(open(sys.argv[1]))["motion_vectors"]["max_px"]))' mv-one/fire_mv.json)
[ "$scales" = "$one $one $one" ] || flunk "the slices' scales are $scales, the one-process render's $one"
pfx_run assemble mv-s -o mv-all
want_status 0
stderr_has "assembled 11 frames of 1 render in 'mv-all' (22 linked"
same_render mv-one mv-all
[ "$(stat -c %h mv-all/fire_mv_0015.png)" -ge 2 ] || flunk "motion-vector frames are not hard links"
end

begin "assemble --atlas: the colour and motion-vector sheets of a one-process render"
pfx_run render "$FIRE" -o mv-one-atlas "${S[@]}" --atlas --crop --padding 3
want_status 0
pfx_run assemble mv-s -o mv-all-atlas --atlas --crop --padding 3
want_status 0
[ -f mv-all-atlas/fire_mv_atlas.png ] || flunk "no fire_mv_atlas.png"
same_render mv-one-atlas mv-all-atlas
end

begin "slices with --mv-max 3 --mv-flip-y: the sidecar of a one-process render"
M=(--size 48x40 --seed 4 -q --frames 10:14 --motion-vectors --mv-max 3 --mv-flip-y)
pfx_run render "$FIRE" -o mx-one "${M[@]}"
want_status 0
for i in 0 1; do
    pfx_run render "$FIRE" -o mx-s$i "${M[@]}" --slice $i/2
    want_status 0
done
pfx_run assemble mx-s0 mx-s1 -o mx-all
want_status 0
same_render mx-one mx-all
grep -q '"max_from": "--mv-max"' mx-all/fire_mv.json || flunk "the sidecar does not say --mv-max"
end

begin "a slice missing a motion-vector frame is an error and writes no manifest"
cp -r mv-s mv-gap && rm mv-gap/fire_mv_0015.png
pfx_run assemble mv-gap -o mv-gap-all
want_status 1
stderr_has "cannot read 'mv-gap/fire_mv_0015.png'"
[ ! -e mv-gap-all/fire.manifest.json ] || flunk "a manifest was written"
end

begin "slices that disagree on the scale are an error"
cp -r mv-s mv-odd
"$py" -c 'import json,sys; p=sys.argv[1]; m=json.load(open(p)); m["slice"]["mv_max_px"] *= 2; json.dump(m, open(p, "w"))' \
    mv-odd/fire.slice-0001-of-0003.manifest.json
pfx_run assemble mv-odd -o mv-odd-all
want_status 1
stderr_has "encodes its motion vectors with a scale of"
[ ! -e mv-odd-all/fire.manifest.json ] || flunk "a manifest was written"
end

# The pass's memory: 52 bytes a pixel (two RGBA32F images, 3 floats and 4
# 16-bit samples), here 48 x 40 x 52 = 99840 bytes; a chunk of 4096 ends of
# 16 bytes and its GL buffer, 131072; the simulation one frame ahead, its
# pools and queues twice (as many as the render's own: the "pools" part
# and the "queues" part, the state's and its view's), and its id index, 8
# bytes a particle of every pool (plus one) and 16 a particle of the
# largest with the radix sort's 256 words a block (plus one block).
mv_part() {
    "$pfx" info "$FIRE" --size 48x40 --seed 4 --format json "$@" | "$py" -c '
import json, sys
d = json.load(sys.stdin)
p, caps = d["memory"]["parts"], [e["capacity"] for e in d["emitters"]]
most = max(caps)
want = 48 * 40 * 52 + 2 * 4096 * 16 + 2 * p["pools"] + p["queues"] + 8 * (sum(caps) + 1) + \
    16 * most + 4 * 256 * (-(-most // 65536) + 1)
print(int(p["motion_vectors"]), int(want), int(d["memory"]["total_bytes"]))'
}
begin "--max-memory counts the motion-vector pass"
read -r part want total <<<"$(mv_part)"
read -r _ _ with <<<"$(mv_part --motion-vectors)"
bound=$((total + 60000))
pfx_run render "$FIRE" -o mem --size 48x40 --seed 4 -q --frames 10:10 --max-memory $bound
want_status 0
pfx_run render "$FIRE" -o mem --size 48x40 --seed 4 -q --frames 10:10 --max-memory $bound --motion-vectors
want_status 1
stderr_has "this render needs up to"
pfx_run render "$FIRE" -o mem --size 48x40 --seed 4 -q --frames 10:10 --max-memory $((with + 1)) --motion-vectors
want_status 0
end

begin "pfx info --motion-vectors shows the pass: pixels, ends, the simulation ahead"
read -r part want _ <<<"$(mv_part --motion-vectors)"
[ "$part" = "$want" ] || flunk "motion_vectors part $part, expected $want"
read -r part _ _ <<<"$(mv_part)"
[ "$part" = 0 ] || flunk "motion_vectors part $part without the option, expected 0"
end

summary
