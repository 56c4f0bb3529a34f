#!/usr/bin/env bash
# render --format exr: the frames read back through OpenEXR's own library
# (tests/jobs/exr_read.c, which knows nothing of pfx) and Debian's
# exrheader, with known answers: channels R, G, B, A in half float, the
# size, ZIP; an additive sprite of colour x intensity 4 keeps its 4 where
# the PNG clips at 255; an alpha-blended one is premultiplied; exposure is
# applied and neither the tone curve nor dither is; the background is
# exactly 0. Then the bytes for --threads 1 and 7, -j, --frames pieces and
# slices (assembled), the manifest, stale PNGs, and the usage errors.
#
#   bash run_exr.sh PATH-TO-PFX SOURCE-DIR   (PFX_EXR_READ: the reader)
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" exr "$@"
cd "$work" || exit 2
reader=${PFX_EXR_READ:-$pfx_dir/tests/exr_read}
[ -x "$reader" ] || { fail "the EXR reader" "no executable '$reader' (PFX_EXR_READ)"; summary; }
FIRE=$src/effects/fire.yaml

# A white texture: a flat sprite whose pixels are its colour exactly.
"$py" -c 'from PIL import Image; Image.new("RGBA", (8, 8), (255,) * 4).save("white.png")'
# Two flat sprites 0.5 m = 16 px wide under an orthographic camera of 2 m
# over 64 px: an additive one of colour (1, 0.5, 0.25) x intensity 4
# centred on pixel (16, 32), and an alpha-blended one of #ff8000 at alpha
# 128/255 on (48, 32), over a transparent background.
scene() { # NAME IMAGE-EXTRA
    cat > "$1.yaml" <<YAML
pfx: 1
duration: 1
fps: 10
seed: 3
camera: { position: [0, 0, 5], target: [0, 0, 0], ortho: 2 }
image: { size: [64, 64], background: "#00000000"$2 }
emitters:
  glow:
    bursts: [{ time: 0, count: 1 }]
    position: [-0.5, 0, 0]
    speed: 0
    lifetime: 10
    size: 0.5
    color: [1, 0.5, 0.25]
    intensity: 4
    blend: add
    texture: white.png
    forces: []
  puff:
    bursts: [{ time: 0, count: 1 }]
    position: [0.5, 0, 0]
    speed: 0
    lifetime: 10
    size: 0.5
    color: "#ff800080"
    blend: alpha
    texture: white.png
    forces: []
YAML
}
scene plain ""
scene graded ", exposure: -1, tonemap: aces, dither: true"

# check NAME.exr NAME.png GAIN: the EXR against the formulas, the PNG
# against what 8 bits can hold.
check() {
    "$reader" "$1" > "$1.txt" || { flunk "exr_read failed on $1"; return; }
    "$py" - "$1.txt" "$2" "$3" <<'PY'
import sys
import numpy as np
from PIL import Image
text, png, gain = sys.argv[1], sys.argv[2], float(sys.argv[3])
lines = open(text).read().split("\n")
head = lines[:lines.index("pixels")]
px = np.array([l.split() for l in lines[len(head) + 1:] if l], dtype=np.float64).reshape(64, 64, 4)
bad = []
if head[0] != "size 64 64" or head[1] != "compression zip":
    bad.append("header %s" % head[:2])
if sorted(head[2:]) != ["channel %s half" % c for c in "ABGR"]:
    bad.append("channels %s" % head[2:])
glow, puff = px[32, 16], px[32, 48]
# Additive: premultiplied colour x intensity x 2^exposure, zero coverage.
want_glow = np.array([4, 2, 1, 0]) * [gain, gain, gain, 1]
if np.abs(glow - want_glow).max() > 1e-3:
    bad.append("additive pixel %s, formula %s" % (glow, want_glow))
# No dither and no tone curve: the inside of each square is one value.
for (x, y), name in [((16, 32), "additive"), ((48, 32), "alpha")]:
    inner = px[y - 6:y + 6, x - 6:x + 6].reshape(-1, 4)
    if np.ptp(inner, axis=0).max() != 0:
        bad.append("%s square not flat: %s .. %s" % (name, inner.min(0), inner.max(0)))
# Alpha blending, premultiplied: RGB = colour x alpha (x 2^exposure), A = alpha.
a = 128 / 255
want_puff = np.array([1 * a * gain, a * a * gain, 0, a])
if np.abs(puff - want_puff).max() > 1e-3:
    bad.append("alpha pixel %s, premultiplied formula %s" % (puff, want_puff))
# The background, outside both squares (2 px margin), is exactly 0.
mask = np.ones((64, 64), bool)
mask[22:42, 6:26] = mask[22:42, 38:58] = False
if np.abs(px[mask]).max() != 0:
    bad.append("background not 0: max %g" % np.abs(px[mask]).max())
# The PNG of the same scene: 8 bits clip the additive light.
p = np.asarray(Image.open(png).convert("RGBA")).astype(int)
if gain == 1 and tuple(p[32, 16]) != (255, 255, 255, 255):
    bad.append("PNG additive pixel %s, expected clipped (255, 255, 255, 255)" % (tuple(p[32, 16]),))
if glow[0] <= 1 or p[32, 16][0] > 255:
    bad.append("EXR red %g should exceed 1 where the PNG holds %d" % (glow[0], p[32, 16][0]))
print("; ".join(bad) if bad else "ok")
PY
}

for s in plain graded; do
    begin "$s: the EXR frame read back: header, additive > 1, premultiplied alpha, exposure, no curve, no dither"
    pfx_run render $s.yaml -o $s-exr --format exr --frames 2:2 -q
    want_status 0
    pfx_run render $s.yaml -o $s-png --frames 2:2 -q
    want_status 0
    gain=1
    [ $s = graded ] && gain=0.5
    got=$(check $s-exr/${s}_0002.exr $s-png/${s}_0002.png $gain)
    [ "$got" = ok ] || flunk "$got"
    end
done

begin "exrheader (Debian's openexr) reads the frame: R G B A half, zip, 64x64"
if command -v exrheader > /dev/null; then
    exrheader plain-exr/plain_0002.exr > hdr.txt 2>&1 || flunk "exrheader failed: $(head -3 hdr.txt)"
    for c in A B G R; do
        grep -q "^    $c, 16-bit floating-point, sampling 1 1" hdr.txt || flunk "no half channel $c"
    done
    grep -q "compression (type compression): zip" hdr.txt || flunk "not zip"
    grep -q "dataWindow (type box2i): (0 0) - (63 63)" hdr.txt || flunk "data window"
    # Rec. 709 primaries with a D65 white: what pfx's linear colour is in.
    grep -A4 "^chromaticities (type chromaticities):" hdr.txt | tr -s ' ' >chroma.txt
    [ "$(sed -n 2,5p chroma.txt)" = " red (0.64 0.33)
 green (0.3 0.6)
 blue (0.15 0.06)
 white (0.3127 0.329)" ] || flunk "chromaticities: $(cat chroma.txt)"
else
    flunk "no exrheader: ./install-deps --test installs openexr"
fi
end

# framesPerSecond: whole rates as N/1, NTSC rates as N000/1001, others in
# lowest terms.
for rate in 24:24/1 29.97:30000/1001 23.976:24000/1001 12.5:25/2; do
    begin "--fps ${rate%%:*}: exrheader shows framesPerSecond ${rate#*:}"
    pfx_run render plain.yaml -o fps-${rate%%:*} --format exr --frames 0:0 --fps "${rate%%:*}" -q
    want_status 0
    exrheader fps-${rate%%:*}/plain_0000.exr >fps.txt 2>&1 || flunk "exrheader failed: $(head -3 fps.txt)"
    grep -q "^framesPerSecond (type rational): ${rate#*:} " fps.txt ||
        flunk "$(grep framesPerSecond fps.txt || echo 'no framesPerSecond')"
    end
done

A=(--size 64x48 --frames 10:17 --seed 5 -q --format exr)
# same_frames DIR: the frames of t1, byte for byte.
same_frames() {
    local f
    for f in t1/fire_*.exr; do
        cmp -s "$f" "$1/${f#t1/}" || flunk "$1/${f#t1/} differs from the --threads 1 frame"
    done
    [ "$(ls "$1"/fire_*.exr | wc -l)" = 8 ] || flunk "$1 holds $(ls "$1"/fire_*.exr | wc -l) frames, not 8"
}
begin "the same EXR bytes for --threads 1 and 7, -j 3, --frames pieces and assembled slices"
pfx_run render "$FIRE" -o t1 "${A[@]}" --threads 1
want_status 0
pfx_run render "$FIRE" -o t7 "${A[@]}" --threads 7
want_status 0
same_frames t7
pfx_run render "$FIRE" -o j3 "${A[@]}" -j 3
want_status 0
same_frames j3
# Two --frames pieces in two directories (one directory would hold only
# the last piece: its manifest makes the first one's frames stale).
pfx_run render "$FIRE" -o p1 "${A[@]/10:17/10:12}"
want_status 0
pfx_run render "$FIRE" -o p2 "${A[@]/10:17/13:17}"
want_status 0
for f in t1/fire_*.exr; do
    cmp -s "$f" "p1/${f#t1/}" || cmp -s "$f" "p2/${f#t1/}" || flunk "the pieces' ${f#t1/} differs"
done
[ "$(ls p1/*.exr p2/*.exr | wc -l)" = 8 ] || flunk "the pieces hold $(ls p1/*.exr p2/*.exr | wc -l) frames"
for i in 0 1 2; do
    pfx_run render "$FIRE" -o s$i "${A[@]}" --slice $i/3
    want_status 0
done
pfx_run assemble s0 s1 s2 -o all
want_status 0
same_frames all
end

begin "the manifest lists the EXR frames with their SHA-256, and format exr"
"$py" - t1/fire.manifest.json <<'PY' > man.txt
import hashlib, json, os, sys
m = json.load(open(sys.argv[1]))
d = os.path.dirname(sys.argv[1])
outs = m["outputs"]
names = [o["path"] for o in outs]
bad = []
if names != ["fire_%04d.exr" % f for f in range(10, 18)]:
    bad.append("outputs %s" % names)
for o in outs:
    if hashlib.sha256(open(os.path.join(d, o["path"]), "rb").read()).hexdigest() != o["sha256"]:
        bad.append("hash of " + o["path"])
if m["settings"].get("format") != "exr":
    bad.append("settings.format %r" % m["settings"].get("format"))
print("; ".join(bad) if bad else "ok")
PY
[ "$(cat man.txt)" = ok ] || flunk "$(cat man.txt)"
pfx_run render "$FIRE" -o t1 "${A[@]}" --threads 1
want_status 0
[ -z "$(ls t1 | grep -v -e '^fire_00[01][0-9]\.exr$' -e '^fire\.manifest\.json$')" ] || flunk "stray files: $(ls t1)"
end

begin "switching a render from PNG to EXR removes the stale PNG frames"
pfx_run render "$FIRE" -o switch --size 64x48 --frames 10:12 -q
want_status 0
pfx_run render "$FIRE" -o switch --size 64x48 --frames 10:12 -q --format exr
want_status 0
[ "$(ls switch | tr '\n' ' ')" = "fire.manifest.json fire_0010.exr fire_0011.exr fire_0012.exr " ] ||
    flunk "left: $(ls switch | tr '\n' ' ')"
end

begin "a frame that cannot be written: exit 1, the path named, no temporary left"
mkdir -p blocked/fire_0011.exr
pfx_run render "$FIRE" -o blocked --size 64x48 --frames 10:12 -q --format exr
want_status 1
stderr_has "fire_0011.exr"
[ -z "$(ls -A blocked | grep tmp)" ] || flunk "temporary left: $(ls -A blocked)"
end

# usage_error WORDS... -- MESSAGE: exit 2 with MESSAGE, and nothing written.
usage() {
    local msg=${*: -1}
    pfx_run "${@:1:$#-1}"
    want_status 2
    stderr_has "$msg"
    [ ! -e bad ] || flunk "the run wrote 'bad'"
}
begin "--format exr with what it cannot honour is a usage error"
usage render "$FIRE" -o bad --format exr --atlas "--atlas cannot go with --format exr"
usage render "$FIRE" -o bad --format exr --preview p.webp "--preview cannot go with --format exr"
usage render "$FIRE" -o bad --alpha straight --format exr "--alpha straight cannot go with --format exr"
usage bake "$FIRE" -o bad.csv --format exr "--format exr is for render's frames"
usage render "$FIRE" -o bad --format tiff "or 'png' or 'exr' (frames), got 'tiff'"
end

begin "--format exr with --alpha premultiplied and JSON diagnostics is fine"
pfx_run render "$FIRE" -o fine --size 32x32 --frames 0:0 -q --format exr --alpha premultiplied --format json
want_status 0
[ -f fine/fire_0000.exr ] || flunk "no frame"
end
summary
