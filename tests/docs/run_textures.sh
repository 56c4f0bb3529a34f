#!/usr/bin/env bash
# The flipbook sheets in effects/textures/ are what tools/make_textures.py
# makes, byte for byte (its noise is seeded, so a rerun must not change a
# committed file, and every file there comes from it), and they keep what
# its header promises: no cell reaches its border (mipmaps do not bleed
# between cells), the normal map holds unit normals facing the camera,
# the fire sheet loops (its last cell steps to its first no more than its
# cells step to each other) and the stone tile tiles (the step across its
# wrapped edge is no larger than the steps inside it).
#
#   bash run_textures.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" textures "$@"
textures=$src/effects/textures
if ! "$py" "$src/tools/make_textures.py" "$work/made" 2>"$work/err"; then
    fail "tools/make_textures.py failed" "$(cat "$work/err")"
else
    begin "tools/make_textures.py remakes effects/textures/ byte for byte"
    for f in "$textures"/*.png "$work"/made/*.png; do
        name=${f##*/}
        if [ ! -f "$work/made/$name" ]; then
            flunk "effects/textures/$name is not made by the script"
        elif [ ! -f "$textures/$name" ]; then
            flunk "the script makes $name, which is not committed"
        elif ! cmp -s "$textures/$name" "$work/made/$name"; then
            flunk "$name differs from what the script makes"
        fi
    done
    end
fi
tally "$("$py" - "$textures" <<'PY'
import os, sys
import numpy as np
from PIL import Image
d = sys.argv[1]
for name, cell in [("fire_sheet.png", 128), ("smoke_puffs.png", 128), ("spark_sheet.png", 32),
                   ("flame_sheet.png", 64), ("smoke_sheet.png", 64)]:
    a = np.asarray(Image.open(os.path.join(d, name)).convert("RGBA"))[..., 3]
    ok = a.shape == (4 * cell, 4 * cell)
    edge = 0
    for r in range(4):
        for c in range(4):
            blk = a[r * cell:(r + 1) * cell, c * cell:(c + 1) * cell]
            edge = max(edge, blk[0].max(), blk[-1].max(), blk[:, 0].max(), blk[:, -1].max())
            ok = ok and blk.max() >= 32  # every cell draws something
    ok = ok and edge == 0
    print(("ok   " if ok else "FAIL ") + f"{name}: 4x4 cells of {cell} px, alpha at the cell borders {edge}")
n = np.asarray(Image.open(os.path.join(d, "smoke_puffs_normal.png")).convert("RGB")) / 255.0 * 2 - 1
length = np.sqrt((n * n).sum(-1))
ok = n.shape[:2] == (512, 512) and np.abs(length - 1).max() < 0.02 and n[..., 2].min() > 0
print(("ok   " if ok else "FAIL ") + f"smoke_puffs_normal.png: unit normals within {np.abs(length - 1).max():.4f}, z > 0")
f = np.asarray(Image.open(os.path.join(d, "fire_sheet.png")).convert("RGBA"), dtype=np.float64)
cells = [f[r * 128:(r + 1) * 128, c * 128:(c + 1) * 128, 3] for r in range(4) for c in range(4)]
steps = [np.abs(cells[k + 1] - cells[k]).mean() for k in range(15)]
seam = np.abs(cells[0] - cells[15]).mean()
print(("ok   " if seam <= 1.2 * max(steps) else "FAIL ")
      + f"fire_sheet.png loops: cell 15 -> 0 differs by {seam:.2f}, steps inside up to {max(steps):.2f}")
t = np.asarray(Image.open(os.path.join(d, "stone_tile.png")).convert("L"), dtype=np.float64)
inside = max(np.abs(np.diff(t, axis=a)).mean() for a in (0, 1))
wrap = max(np.abs(t[0] - t[-1]).mean(), np.abs(t[:, 0] - t[:, -1]).mean())
print(("ok   " if wrap <= 1.5 * inside else "FAIL ")
      + f"stone_tile.png tiles: the wrapped edge steps {wrap:.2f}, rows and columns inside {inside:.2f}")
PY
)"
summary
