#!/usr/bin/env bash
# --atlas: the sheet and its JSON read back by readers pfx has no part in
# (Pillow for the PNGs, Python's json): every frame rectangle holds that
# frame's pixels exactly (alpha, and colour where alpha > 0), the gutter beyond the extruded ring is
# transparent, the ring repeats the frame's edge, no transparent pixel near
# a visible one is left black (colour bleed), --crop keeps every visible
# pixel, and the numbers each engine asks for agree with the grid.
#
#   bash run_atlas.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" atlas "$@"
cd "$work" || exit 2
FIRE=$src/effects/fire.yaml
A=(--size 48x40 --frames 10:20 --seed 4 -q)

# check DIR PADDING EXTRUDE COLS ROWS CROP
check() {
    "$py" - "$@" <<'PY'
import json, sys
from PIL import Image
import numpy as np
d, pad, ext, cols, rows, crop = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), sys.argv[6] == "1"
meta = json.load(open(d + "/fire_atlas.json"))
sheet = np.asarray(Image.open(d + "/fire_atlas.png").convert("RGBA")).astype(int)
bad = []
g = meta["grid"]
names = list(meta["frames"])
if (g["columns"], g["rows"]) != (cols, rows) or g["frames"] != len(names) != 11:
    bad.append("grid %s" % g)
if (meta["unity"]["tiles_x"], meta["unity"]["tiles_y"], meta["unreal"]["sub_images_horizontal"],
        meta["godot"]["v_frames"]) != (cols, rows, cols, rows) or meta["meta"]["alpha"] != "straight":
    bad.append("engine numbers %s %s %s" % (meta["unity"], meta["unreal"], meta["godot"]))
if sheet.shape[:2] != (meta["meta"]["size"]["h"], meta["meta"]["size"]["w"]) or \
        sheet.shape[:2] != (rows * g["cell"]["h"], cols * g["cell"]["w"]):
    bad.append("sheet %s" % (sheet.shape,))
near_black = 0
for k, name in enumerate(names):
    f = meta["frames"][name]
    r, src = f["frame"], f["spriteSourceSize"]
    frame = np.asarray(Image.open(d + "/" + name).convert("RGBA")).astype(int)
    part = frame[src["y"]:src["y"] + src["h"], src["x"]:src["x"] + src["w"]]
    if crop and (frame[:, :, 3].sum() != part[:, :, 3].sum()):
        bad.append("%s: the crop cuts visible pixels" % name)
    cx, cy = (k % cols) * g["cell"]["w"], (k // cols) * g["cell"]["h"]
    if (r["x"], r["y"]) != (cx + pad, cy + pad):
        bad.append("%s at %s" % (name, r))
    cell = sheet[cy:cy + g["cell"]["h"], cx:cx + g["cell"]["w"]]
    inner = cell[pad:pad + r["h"], pad:pad + r["w"]]
    # Equal as images: the same alpha, and the same colour where alpha > 0
    # (bleeding gives fully transparent pixels colour; that is its point).
    same = lambda x, y: np.array_equal(x[..., 3], y[..., 3]) and \
        np.array_equal(x[..., :3][x[..., 3] > 0], y[..., :3][y[..., 3] > 0])
    if not same(inner, part):
        bad.append("%s: its rectangle is not the frame" % name)
    if ext and pad:
        if not (same(cell[pad - 1, pad:pad + r["w"]], part[0]) and
                same(cell[pad:pad + r["h"], pad + r["w"]], part[:, -1])):
            bad.append("%s: the ring does not repeat the edge" % name)
    e = min(ext, pad)
    gutter = np.ones(cell.shape[:2], bool)
    gutter[pad - e:pad + r["h"] + e, pad - e:pad + r["w"] + e] = False
    if cell[gutter][:, 3].any():
        bad.append("%s: the gutter is not transparent" % name)
    # Bleed: a transparent pixel next to a visible one carries colour.
    a = cell[:, :, 3] > 0
    nb = np.zeros_like(a)
    nb[1:, :] |= a[:-1, :]; nb[:-1, :] |= a[1:, :]; nb[:, 1:] |= a[:, :-1]; nb[:, :-1] |= a[:, 1:]
    edge = (~a) & nb
    near_black += int((cell[edge][:, :3].sum(axis=1) == 0).sum())
if near_black:
    bad.append("%d transparent pixels beside visible ones are black" % near_black)
print(("FAIL %s: " % d + "; ".join(bad)) if bad else
      "ok   %s: %d frames in %dx%d cells, pixels, gutter, ring and bleed as stated" % (d, len(names), cols, rows))
PY
}

begin "--atlas: a grid from the frame count"
pfx_run render "$FIRE" -o a "${A[@]}" --atlas
want_status 0
[ -f a/fire_atlas.png ] && [ -f a/fire_atlas.json ] || flunk "no atlas"
grep -q '"fire_atlas.png"' a/fire.manifest.json && grep -q '"fire_atlas.json"' a/fire.manifest.json ||
    flunk "the manifest does not list the atlas"
end
tally "$(check a 2 1 4 3 0)"

begin "--atlas 6x2 --padding 3 --extrude 2"
pfx_run render "$FIRE" -o b "${A[@]}" --atlas 6x2 --padding 3 --extrude 2
want_status 0
end
tally "$(check b 3 2 6 2 0)"

begin "--atlas=11x1 --padding 0 --crop"
pfx_run render "$FIRE" -o c "${A[@]}" --atlas=11x1 --padding 0 --crop
want_status 0
"$py" -c 'import json,sys; m=json.load(open("c/fire_atlas.json")); f=m["frames"]["fire_0010.png"]; sys.exit(not (f["trimmed"] and f["frame"]["w"] < 48))' ||
    flunk "the frames were not cropped"
end
tally "$(check c 0 1 11 1 1)"

begin "a premultiplied render makes a premultiplied sheet, without bleed"
# The explosion on a transparent background: alpha-blended smoke (bleed
# has texels to fill) and additive fire (light with alpha 0).
sed '/^  background:/d' "$src/effects/explosion.yaml" >boom.yaml
ln -s "$src/effects/textures" textures
pfx_run render boom.yaml -o pm "${A[@]}" --atlas --alpha premultiplied
want_status 0
out=$("$py" - <<'PY'
import json
from PIL import Image
import numpy as np
meta = json.load(open("pm/boom_atlas.json"))
sheet = np.asarray(Image.open("pm/boom_atlas.png").convert("RGBA")).astype(float)
bad = []
if meta["meta"]["alpha"] != "premultiplied":
    bad.append("the JSON says alpha %r" % meta["meta"]["alpha"])
# Premultiplied over a colour C: rgb + C (1 - a). The sheet over C, cell by
# cell, must be the frame over C where the frame is, and C in the gutter.
C = np.array([40.0, 160.0, 90.0])
over = lambda im: im[..., :3] + C * (1 - im[..., 3:4] / 255)
g = meta["grid"]
outside = np.ones(sheet.shape[:2], bool)  # texels no frame or ring covers
for k, name in enumerate(meta["frames"]):
    r = meta["frames"][name]["frame"]
    frame = np.asarray(Image.open("pm/" + name).convert("RGBA")).astype(float)
    if np.abs(over(sheet[r["y"]:r["y"] + r["h"], r["x"]:r["x"] + r["w"]]) - over(frame)).max() > 1e-9:
        bad.append("%s over a colour differs from its frame over it" % name)
    e = g["extrude"]
    outside[r["y"] - e:r["y"] + r["h"] + e, r["x"] - e:r["x"] + r["w"] + e] = False
if np.abs(over(sheet[outside]) - C).max() > 0:
    bad.append("the gutters over a colour are not that colour")
# Alpha-0 texels beyond the frames: no light. (Inside them, a frame's own
# additive light has alpha 0, and the comparison above covers it.)
zero = sheet[outside & (sheet[..., 3] == 0)][:, :3]
if not zero.size or zero.any():
    bad.append("alpha-0 texels beyond the frames carry colour: mean RGB %.4f" % zero.mean())
print(("FAIL premultiplied sheet: " + "; ".join(bad)) if bad else
      "ok   premultiplied sheet: over a colour it is the frames over it; alpha-0 texels beyond them are black")
PY
)
case $out in ok*) ;; *) flunk "$out" ;; esac
end

begin "assemble --atlas of premultiplied slices: the same premultiplied sheet"
pfx_run render boom.yaml -o pms "${A[@]}" --alpha premultiplied --slice 0/2
pfx_run render boom.yaml -o pms "${A[@]}" --alpha premultiplied --slice 1/2
pfx_run assemble pms -o pma --atlas
want_status 0
cmp -s pma/boom_atlas.png pm/boom_atlas.png || flunk "the sheet differs from the one-process render's"
grep -q '"alpha": "premultiplied"' pma/boom_atlas.json || flunk "the JSON does not say premultiplied"
end

begin "--atlas-pot: power-of-two sides, the UV rectangles on the cells"
pfx_run render "$FIRE" -o pot "${A[@]}" --atlas --atlas-pot
want_status 0
out=$("$py" - <<'PY'
import json
from PIL import Image
import numpy as np
meta = json.load(open("pot/fire_atlas.json"))
sheet = np.asarray(Image.open("pot/fire_atlas.png").convert("RGBA")).astype(int)
h, w = sheet.shape[:2]
g, bad = meta["grid"], []
if (w, h) != (256, 256) or (meta["meta"]["size"]["w"], meta["meta"]["size"]["h"]) != (w, h):
    bad.append("the sheet is %dx%d, the JSON says %s (want 256x256: 4x3 cells of 52x44)"
               % (w, h, meta["meta"]["size"]))
if (g["used"]["w"], g["used"]["h"]) != (4 * 52, 3 * 44):
    bad.append("used %s" % g["used"])
for k, name in enumerate(meta["frames"]):
    f = meta["frames"][name]
    r, uv = f["frame"], f["uv"]
    if (uv["x"] * w, uv["y"] * h, uv["w"] * w, uv["h"] * h) != (r["x"], r["y"], r["w"], r["h"]):
        bad.append("%s: uv %s is not %s" % (name, uv, r))
    if (r["x"], r["y"]) != ((k % 4) * 52 + 2, (k // 4) * 44 + 2):
        bad.append("%s at %s" % (name, r))
    frame = np.asarray(Image.open("pot/" + name).convert("RGBA")).astype(int)
    part = sheet[r["y"]:r["y"] + r["h"], r["x"]:r["x"] + r["w"]]
    if not np.array_equal(part[..., 3], frame[..., 3]) or \
            not np.array_equal(part[..., :3][part[..., 3] > 0], frame[..., :3][frame[..., 3] > 0]):
        bad.append("%s: its rectangle is not the frame" % name)
if sheet[:, 4 * 52:].any() or sheet[3 * 44:, :].any():
    bad.append("the padding beyond the grid is not transparent black")
print(("FAIL --atlas-pot: " + "; ".join(bad)) if bad else "ok")
PY
)
case $out in ok*) ;; *) flunk "$out" ;; esac
end

begin "--atlas-json array: TexturePacker's array, the same as the hash"
pfx_run render "$FIRE" -o arr "${A[@]}" --atlas --atlas-json array
want_status 0
"$py" - <<'PY' || flunk "the array JSON does not match the hash JSON"
import json, sys
h = json.load(open("a/fire_atlas.json"))
a = json.load(open("arr/fire_atlas.json"))
assert isinstance(a["frames"], list) and len(a["frames"]) == len(h["frames"]) == 11
for entry, name in zip(a["frames"], h["frames"]):
    entry = dict(entry)
    assert entry.pop("filename") == name, name
    assert entry == h["frames"][name], name
assert a["meta"] == h["meta"] and a["grid"] == h["grid"]
PY
cmp -s arr/fire_atlas.png a/fire_atlas.png || flunk "the sheets differ"
end

begin "--atlas-pot with --motion-vectors: both sheets padded alike"
pfx_run render "$FIRE" -o potmv "${A[@]}" --atlas --atlas-pot --motion-vectors
want_status 0
"$py" -c 'from PIL import Image; import sys; sys.exit(not (Image.open("potmv/fire_atlas.png").size == Image.open("potmv/fire_mv_atlas.png").size == (256, 256)))' ||
    flunk "the sheets are not both 256x256"
end

begin "--atlas-json with a bad form is a usage error"
pfx_run render "$FIRE" -o u "${A[@]}" --atlas --atlas-json list
want_status 2
stderr_has "--atlas-json takes 'hash' or 'array', got 'list'"
end

begin "a render without --atlas removes the old sheet"
pfx_run render "$FIRE" -o a "${A[@]}"
want_status 0
[ ! -e a/fire_atlas.png ] && [ ! -e a/fire_atlas.json ] || flunk "the old atlas is still there"
end

# The sheet, the motion-vector sheet and the JSON naming them appear
# together: a render whose motion-vector sheet cannot be written (past
# ulimit -f, which fails like a full disk; the 16-bit sheet is the larger)
# leaves the previous three as they were, not the old sheet replaced and
# then removed.
begin "an atlas whose motion-vector sheet fails: the previous sheet, mv sheet and JSON stay whole"
B=(--size 64x64 --frames 0:15 --atlas --motion-vectors -q)
pfx_run render "$FIRE" -o grp "${B[@]}" --seed 1
want_status 0
sha256sum grp/fire_atlas.png grp/fire_mv_atlas.png grp/fire_atlas.json >grp.sha
c=$(stat -c %s grp/fire_atlas.png) m=$(stat -c %s grp/fire_mv_atlas.png)
[ $((m * 10)) -gt $((c * 13)) ] || flunk "the sheets are too close in size to part them: $c, $m"
(ulimit -f $(((c + m) / 2048)) && exec "$pfx" render "$FIRE" -o grp "${B[@]}" --seed 2) >out 2>err
status=$?
want_status 1
stderr_has "cannot write 'grp/fire_mv_atlas.png': File too large"
sha256sum --quiet -c grp.sha >/dev/null 2>&1 ||
    flunk "the previous set changed: $(sha256sum -c grp.sha 2>&1 | tr '\n' ' ')"
ls -a grp | grep -q '\.tmp-' && flunk "temporaries left: $(ls -a grp | grep '\.tmp-')"
pfx_run render "$FIRE" -o grp "${B[@]}" --seed 2
want_status 0
[ "$(sha256sum -c grp.sha 2>/dev/null | grep -c ': OK$')" = 0 ] ||
    flunk "without the limit, seed 2 did not replace all three"
end

begin "an atlas over 16384 pixels fails before rendering"
pfx_run render "$FIRE" -o big --size 2000x2000 --frames 0:80 --atlas
want_status 1
stderr_has "is 18036x18036, over the 16384 limit"
[ -z "$(ls big 2>/dev/null)" ] || flunk "files were written: $(ls big | head -3)"
end

begin "a grid too small for the frames"
pfx_run render "$FIRE" -o small "${A[@]}" --atlas 3x3
want_status 1
stderr_has "an atlas of 3x3 cells cannot hold 11 frames"
end

begin "--atlas with a bad grid is a usage error"
pfx_run render "$FIRE" -o u "${A[@]}" --atlas=0x3
want_status 2
stderr_has "--atlas takes COLSxROWS, such as 8x8, got '0x3'"
end

summary
