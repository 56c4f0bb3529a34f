#!/usr/bin/env bash
# --preview out.webp, read back by libwebp's own tools (webpinfo validates
# the file, webpmux -info counts its frames) and by Pillow, which decodes
# every frame: each must equal its PNG (alpha, and colour where alpha > 0;
# the preview is lossless), with 1/fps between frames and looping for ever.
#
#   bash run_preview.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" preview "$@"
cd "$work" || exit 2
FIRE=$src/effects/fire.yaml

begin "render --preview"
pfx_run render "$FIRE" -o f --frames 5:16 --size 48x48 --fps 25 --preview f/fire.webp
want_status 0
stderr_has "preview 'f/fire.webp'"
end

begin "webpinfo and webpmux read it: 12 frames, animated, looping"
if command -v webpinfo >/dev/null && command -v webpmux >/dev/null; then
    webpinfo f/fire.webp >info.txt 2>&1 || flunk "webpinfo rejects it: $(tail -3 info.txt)"
    grep -q "Animation: 1" info.txt || flunk "not animated"
    webpmux -info f/fire.webp >mux.txt 2>&1 || flunk "webpmux rejects it"
    grep -q "Number of frames: 12" mux.txt || flunk "$(grep 'Number of frames' mux.txt)"
    grep -q "Loop Count : 0" mux.txt || flunk "does not loop for ever"
else
    flunk "webpinfo or webpmux is missing (Debian's webp; ./install-deps --test)"
fi
end

out=$("$py" - <<'PY'
from PIL import Image
import numpy as np
im = Image.open("f/fire.webp")
bad = []
if getattr(im, "n_frames", 1) != 12:
    bad.append("%d frames" % getattr(im, "n_frames", 1))
for k in range(min(12, getattr(im, "n_frames", 1))):
    im.seek(k)
    got = np.asarray(im.convert("RGBA")).astype(int)
    want = np.asarray(Image.open("f/fire_%04d.png" % (5 + k)).convert("RGBA")).astype(int)
    if got.shape != want.shape or not np.array_equal(got[..., 3], want[..., 3]) or \
            not np.array_equal(got[..., :3][got[..., 3] > 0], want[..., :3][want[..., 3] > 0]):
        bad.append("frame %d differs" % k)
    if im.info.get("duration") not in (40,):
        bad.append("frame %d lasts %s ms" % (k, im.info.get("duration")))
print(("FAIL the frames through Pillow: " + "; ".join(bad)) if bad else
      "ok   Pillow decodes 12 frames of 40 ms equal to the PNGs")
PY
)
tally "$out"

# The explosion on a transparent background: alpha-blended smoke and
# additive fire, whose light has alpha 0.
sed '/^  background:/d' "$src/effects/explosion.yaml" >boom.yaml
ln -s "$src/effects/textures" textures
begin "a premultiplied render: the WebP holds the frames' light"
pfx_run render boom.yaml -o pm --size 64x48 --frames 0:29 --fps 25 --alpha premultiplied \
    --preview pm/boom.webp
want_status 0
end
# Premultiplied frames over black are their RGB; the WebP (straight)
# decoded by Pillow over black is RGB x A / 255. Equal within rounding.
# (The encoder merges equal frames into one of a longer duration: frame k
# is the one shown at 40 k ms.)
out=$("$py" - <<'PY'
from PIL import Image
import numpy as np
im = Image.open("pm/boom.webp")
shown = []
for j in range(im.n_frames):
    im.seek(j)
    im.load()
    shown += [j] * (im.info["duration"] // 40)
worst, got_sum, want_sum = 0, 0.0, 0.0
for k in range(30):
    im.seek(shown[k])
    got = np.asarray(im.convert("RGBA")).astype(float)
    got = got[..., :3] * got[..., 3:] / 255
    want = np.asarray(Image.open("pm/boom_%04d.png" % k).convert("RGBA")).astype(float)[..., :3]
    worst = max(worst, np.abs(got - want).max())
    got_sum, want_sum = got_sum + got.mean(), want_sum + want.mean()
ok = worst <= 1 and want_sum > 0
print("%s premultiplied WebP over black: mean light %.3f against %.3f, worst pixel off by %.1f"
      % ("ok  " if ok else "FAIL", got_sum / 30, want_sum / 30, worst))
PY
)
tally "$out"

begin "--preview-quality 50: a lossy WebP, smaller, decoding close to the lossless one"
pfx_run render "$FIRE" -o q --frames 5:16 --size 128x128 --fps 25 --preview q/fire.webp --preview-quality 50
want_status 0
pfx_run render "$FIRE" -o l --frames 5:16 --size 128x128 --fps 25 --preview l/fire.webp
want_status 0
"$py" - <<'PY' || flunk "not smaller, or not close"
import os, sys
from PIL import Image
import numpy as np
a, b = Image.open("l/fire.webp"), Image.open("q/fire.webp")
assert os.path.getsize("q/fire.webp") < 0.75 * os.path.getsize("l/fire.webp"), "not smaller"
assert b.n_frames == 12
for k in range(12):
    a.seek(k); b.seek(k)
    x, y = (np.asarray(i.convert("RGBA")).astype(float) for i in (a, b))
    # Compared as seen: over black, where lossy RGB under alpha 0 is hidden.
    x, y = x[..., :3] * x[..., 3:] / 255, y[..., :3] * y[..., 3:] / 255
    assert np.abs(x - y).mean() < 3, "frame %d: %.2f" % (k, np.abs(x - y).mean())
PY
webpinfo q/fire.webp 2>&1 | grep -q "Lossy" || flunk "webpinfo does not call it lossy"
end

begin "--preview-quality out of range is a usage error"
pfx_run render "$FIRE" -o q2 --preview q2/fire.webp --preview-quality 101
want_status 2
stderr_has "--preview-quality takes a number from 0 to 100, got '101'"
end

begin "--preview-quality without --preview is a usage error"
pfx_run render "$FIRE" -o q3 --preview-quality 40
want_status 2
stderr_has "--preview-quality goes with --preview"
[ -e q3 ] && flunk "q3 was created"
end

# The smoke's opaque background makes every frame change the whole width,
# which libwebp refuses (a frame that changes less is cropped, and may
# pass: the limit is refused whatever the content).
begin "a WebP over 16383 pixels a side is refused before any frame"
start=$(date +%s%N)
pfx_run render "$src/effects/smoke.yaml" -o wide --size 16384x64 --frames 0:59 --preview wide/smoke.webp
ms=$((($(date +%s%N) - start) / 1000000))
want_status 1
stderr_has "cannot write 'wide/smoke.webp': WebP frames are at most 16383 pixels a side, and these are 16384x64"
[ -z "$(ls wide 2>/dev/null)" ] || flunk "files were written: $(ls wide | head -3)"
[ "$ms" -lt 5000 ] || flunk "it took $ms ms"
end

begin "assemble: a WebP over 16383 pixels a side is refused before gathering"
pfx_run render "$FIRE" -o ws --size 16384x64 --frames 0:1 --slice 0/2 -q
pfx_run render "$FIRE" -o ws --size 16384x64 --frames 0:1 --slice 1/2 -q
pfx_run assemble ws -o wa --preview wa/fire.webp
want_status 1
stderr_has "cannot write 'wa/fire.webp': WebP frames are at most 16383 pixels a side, and these are 16384x64"
[ -z "$(ls wa 2>/dev/null)" ] || flunk "files were gathered: $(ls wa | head -3)"
end

# An intact preview is hashed once, to find it intact, and that hash is
# the one recorded: inotify counts the opens of the file (2 before).
begin "assemble again: an intact preview is read once and kept, its SHA-256 recorded"
pfx_run render "$FIRE" -o as --size 48x48 --frames 0:3 --slice 0/2 -q
pfx_run render "$FIRE" -o as --size 48x48 --frames 0:3 --slice 1/2 -q
pfx_run assemble as -o aa --preview aa/fire.webp -q
want_status 0
before=$(stat -c %Y.%s aa/fire.webp 2>/dev/null)
opens=$("$py" "$src/tests/jobs/count_opens.py" aa/fire.webp "$pfx" assemble as -o aa \
    --preview aa/fire.webp -q)
[ "$opens" = "1 0" ] || flunk "opens and status: $opens, want '1 0'"
[ "$(stat -c %Y.%s aa/fire.webp)" = "$before" ] || flunk "the preview was written again"
"$py" -c 'import hashlib, json, sys
m = json.load(open("aa/fire.manifest.json"))
sys.exit(m["preview"]["sha256"] != hashlib.sha256(open("aa/fire.webp", "rb").read()).hexdigest())' ||
    flunk "the manifest's preview hash is not the file's"
end

begin "--preview needs a .webp or .mp4 path"
pfx_run render "$FIRE" -o g --preview g/fire.gif
want_status 2
stderr_has "--preview writes an animated WebP or an MP4: give a path ending in '.webp' or '.mp4', got 'g/fire.gif'"
end

begin "a deleted preview is made again though the frames are up to date"
rm f/fire.webp
pfx_run render "$FIRE" -o f --frames 5:16 --size 48x48 --fps 25 --preview f/fire.webp
want_status 0
[ -s f/fire.webp ] || flunk "no preview"
end

summary
