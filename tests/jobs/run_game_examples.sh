#!/usr/bin/env bash
# The two examples made for game teams, effects/muzzle_flash.yaml and
# effects/impact.yaml, deliver what their comments promise, through
# `pfx render --atlas --motion-vectors` as a game team would run it, read
# back with Pillow: a premultiplied atlas of the promised grid whose JSON
# says so; a first frame whose flash is additive light (colour with no
# coverage, so it adds under "one, one minus source alpha") that is orange
# to yellow, not white; smoke or dust with coverage in the middle of the
# sequence; motion vectors with coverage where the smoke is; and a last
# frame (nearly) empty, so a one-shot flipbook ends without a pop.
#
#   bash run_game_examples.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" game_examples "$@"
for spec in "muzzle_flash 16 4 8" "impact 24 5 12"; do
    read -r name frames cols mid <<<"$spec"
    begin "$name: renders $frames frames, an atlas and motion vectors"
    pfx_run render "$src/effects/$name.yaml" -o "$work/$name" --atlas --motion-vectors -q
    want_status 0
    stderr_empty
    end
    tally "$("$py" - "$work/$name" "$name" "$frames" "$cols" "$mid" <<'PY'
import colorsys, json, os, sys
import numpy as np
from PIL import Image
out, name, frames, cols, mid = sys.argv[1], sys.argv[2], *map(int, sys.argv[3:])
def check(ok, what):
    print(("ok   " if ok else "FAIL ") + f"{name}: {what}")
def frame(k, mv=False):
    path = os.path.join(out, f"{name}{'_mv' if mv else ''}_{k:04d}.png")
    return np.asarray(Image.open(path).convert("RGBA"), dtype=np.float64) / 255
meta = json.load(open(os.path.join(out, f"{name}_atlas.json")))
grid = meta["grid"]
check(meta["meta"]["alpha"] == "premultiplied" and grid["frames"] == frames
      and (grid["columns"], grid["rows"]) == (cols, cols),
      f"a premultiplied {grid['columns']}x{grid['rows']} atlas of {grid['frames']} frames")
f0 = frame(0)
light = f0[..., :3].max(-1)
additive = (light > f0[..., 3] + 0.1).sum()
check(additive > 500, f"frame 0: {additive} px of additive light (colour above coverage)")
# the flash's hue where it is bright but below white: the tone curve keeps it
ring = (light > 0.35) & (light < 0.97)
h = [colorsys.rgb_to_hsv(*px)[0] * 360 for px in f0[ring][:, :3]]
hue, sat = np.median(h), np.median([colorsys.rgb_to_hsv(*px)[1] for px in f0[ring][:, :3]])
check(ring.sum() > 100 and 15 <= hue <= 60 and sat > 0.25,
      f"frame 0: the flash's glow is orange-yellow, median hue {hue:.0f} deg, saturation {sat:.2f}")
m = frame(mid)
check(m[..., 3].sum() > 300, f"frame {mid}: smoke or dust covers {m[..., 3].sum():.0f} px")
mv = frame(mid, mv=True)
check((mv[..., 3] > 0).sum() > 300, f"frame {mid}: motion vectors cover {(mv[..., 3] > 0).sum()} px")
last = frame(frames - 1)
check(last.max() < 0.2 and last[..., 3].sum() < 40,
      f"frame {frames - 1}: nearly empty (peak {last.max():.2f}, coverage {last[..., 3].sum():.1f} px)")
PY
)"
done
summary
