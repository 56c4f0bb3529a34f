#!/usr/bin/env bash
# Issue 26: the fire examples' cores must not flatten to white. Each of
# fire, fire_loop, campfire and explosion is rendered through pfx render at
# a frame where its flame or fireball burns, in premultiplied alpha (so a
# pixel is the light as seen over black, whatever the background), and
# read with Pillow: the brightest 2 % of its lit pixels must keep a fire's
# hue (median 15 to 45 degrees) and saturation (median at least 0.5). A
# white core has a saturation near 0: the examples before preserve_hue had
# 0.07 (fire), 0.09 (campfire), 0.42 (explosion) and 0.44 (fire_loop).
#
#   bash run_fire_cores.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" fire_cores "$@"
for spec in fire:60 fire_loop:30 campfire:90 explosion:12; do
    name=${spec%%:*} frame=${spec#*:}
    begin "$name: renders frame $frame"
    pfx_run render "$src/effects/$name.yaml" -o "$work/$name" --frames "$frame:$frame" \
        --alpha premultiplied -q
    want_status 0
    end
    png=$(printf '%s/%s/%s_%04d.png' "$work" "$name" "$name" "$frame")
    tally "$("$py" - "$png" "$name" <<'PY'
import colorsys, sys
import numpy as np
from PIL import Image
path, name = sys.argv[1], sys.argv[2]
f = np.asarray(Image.open(path).convert("RGB"), dtype=np.float64) / 255
light = f.max(-1)
top = light >= np.quantile(light[light > 0.05], 0.98)
hsv = np.array([colorsys.rgb_to_hsv(*px) for px in f[top]])
hue, sat = np.median(hsv[:, 0]) * 360, np.median(hsv[:, 1])
ok = top.sum() >= 100 and 15 <= hue <= 45 and sat >= 0.5
print(("ok   " if ok else "FAIL ") + f"{name}: its brightest {top.sum()} px keep a fire's colour, "
      f"median hue {hue:.1f} deg, saturation {sat:.2f} (white would be 0)")
PY
)"
done
summary
