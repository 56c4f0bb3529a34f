"""Known answers for the mip level a textured sprite reads, through the
command line (`pfx render`): one sprite under an orthographic camera of 2 m
over 64 px (32 px per metre), textured with a 64x64 image whose channels
are the low bits of the texel's column: red bit 0, green bit 1, blue bit 2
(0 or 255). A mipmap averages 2x2 texels, so level k of it keeps the
stripes of the channels c >= k (a channel c's stripes are 2^(c - k) texels
wide there) and holds every channel c < k at exactly 0.5. Which channels
are striped in the frame therefore says which level was read.

A sprite facing the camera, 64 / 2^lambda pixels wide, has the level of
detail lambda (the GL specification's log2 of texels per pixel; the man
page's `texture`). For a whole lambda = k the sprite's pixel centres fall
on level k's texel centres, so the frame is level k itself: channels c >= k
at 0 or 255, channels c < k at 128. Between whole levels pfx reads GL's
nearest level (k for lambda in [k - 0.5, k + 0.5)) except within 1/8 of a
half-way point, where it blends the two across that band: at lambda = 1.25
level 1 alone, at 1.75 level 2 alone, at 1.5 half of each. A textured
ribbon follows the same rule at each pixel. The levels themselves are
pfx's: each texel the mean of the 2 x 2 above it, rounded half up.

usage: check_mip.py PFX WORKDIR"""
import os
import subprocess
import sys

import numpy as np
from PIL import Image

from looklib import check, failures, render_effect, rgba

PFX, WORK = sys.argv[1], sys.argv[2]


HEAD = """pfx: 1
duration: 1
fps: 10
seed: 3
camera: { position: [0, 0, 5], target: [0, 0, 0], ortho: 2 }
image: { size: [64, 64], background: "#000000ff", tonemap: none, dither: false }
emitters:
  one:
    bursts: [{ time: 0, count: 1 }]
    position: [0, 0, 0]
    speed: 0
    spread: 0
    lifetime: 10
    color: "#ffffffff"
    blend: alpha
    angle: 0
    forces: []
"""


def render(name, keys):
    """Renders the one sprite with `keys` added and returns frame 0 as an
    int array (H, W, 4)."""
    text = HEAD + "".join(f"    {k}\n" for k in keys)
    return rgba(render_effect(PFX, WORK, name, text, ["--frames", "0:0"])[0], np.int64)


def bits_image(cells):
    """cells copies side by side of the 64x64 bit-stripe image."""
    x = np.arange(64 * cells) % 64
    img = np.zeros((64, 64 * cells, 4), np.uint8)
    for c in range(3):
        img[:, :, c] = ((x >> c) & 1)[None, :] * 255
    img[:, :, 3] = 255
    return Image.fromarray(img)


bits_image(1).save(os.path.join(WORK, "bits.png"))
bits_image(2).save(os.path.join(WORK, "bits2.png"))


def inside(frame, half_px):
    """The sprite's pixels, a pixel in from its edge (clamping and the
    background stay out), for a sprite half_px pixels either side of the
    image centre."""
    lo, hi = int(np.ceil(32 - half_px)) + 1, int(np.floor(32 + half_px)) - 1
    return frame[lo:hi, lo:hi, :3]


def flat(px, c):
    return np.abs(px[..., c] - 128).max() <= 1


def two_valued(px, c):
    v = px[..., c]
    return bool(np.all((v <= 1) | (v >= 254))) and v.min() <= 1 and v.max() >= 254


# Whole levels 0..3: the frame is level k.
for k in range(4):
    px = inside(render(f"level{k}", [f"size: {2 / 2 ** k}", "texture: bits.png"]), 32 / 2 ** k)
    ok = all(two_valued(px, c) if c >= k else flat(px, c) for c in range(3))
    check(ok, f"lambda {k} ({64 // 2 ** k} px over 64 texels) reads level {k}: channels "
              f"{', '.join(f'{c} in {px[..., c].min()}..{px[..., c].max()}' for c in range(3))}")

# The levels' texels: pfx makes the mipmaps (not the GL implementation),
# each texel of level k + 1 the mean of the 2 x 2 under it in level k,
# rounded half up. A seeded noise texture drawn at whole lambda = k shows
# level k texel for texel, so the frame must equal that chain worked out
# here.
rng = np.random.default_rng(27)
noise = rng.integers(0, 256, (64, 64, 4), dtype=np.uint8)
noise[..., 3] = 255
Image.fromarray(noise).save(os.path.join(WORK, "noise.png"))
level = noise[..., :3].astype(np.int64)
for k in range(1, 4):
    level = (level[0::2, 0::2] + level[1::2, 0::2] + level[0::2, 1::2] + level[1::2, 1::2] + 2) // 4
    n = 64 >> k
    f = render(f"noise{k}", [f"size: {2 / 2 ** k}", "texture: noise.png"])
    worst = np.abs(f[32 - n // 2:32 + n // 2, 32 - n // 2:32 + n // 2, :3] - level).max()
    check(worst == 0, f"level {k} of a noise texture is the rounded mean of 2 x 2 texels of "
                      f"level {k - 1}, texel for texel: largest difference {worst}")

# Between levels 1 and 2. Green (bit 1) is striped on level 1 (one texel
# each) and 0.5 on level 2; red is 0.5 on both. Pixels no longer fall on
# texel centres, so a bilinear read of level 1's green lies anywhere in
# 0..255, and a blend of weight w towards level 2 within 128 +- 127.5 (1 - w).
for lam, w, what in [(1.25, 0.0, "level 1 alone"), (1.5, 0.5, "half level 1, half level 2"),
                     (1.75, 1.0, "level 2 alone")]:
    half = 32 / 2 ** lam
    px = inside(render(f"lambda{lam}", [f"size: {2 / 2 ** lam}", "texture: bits.png"]), half)
    g = px[..., 1]
    reach = np.abs(g - 127.5).max()
    # The green reached: at most 127.5 (1 - w) from 0.5, and most of it on
    # this many pixels (a pixel centre near a texel centre).
    ok = flat(px, 0) and reach <= 127.5 * (1 - w) + 1 and reach >= 0.8 * 127.5 * (1 - w)
    check(ok, f"lambda {lam} reads {what}: red {px[..., 0].min()}..{px[..., 0].max()}, "
              f"green within {reach:.1f} of 127.5 (formula {127.5 * (1 - w):.1f})")

# A flipbook cell is the texture: 2 cells of 64x64 side by side in a
# 128x64 sheet, the sprite 16 px wide: lambda = log2(64 / 16) = 2 (not the
# sheet's 128 / 16, which would read level 3 and flatten blue).
px = inside(render("cell", ["size: 0.5", "texture: bits2.png",
                            "flipbook: { grid: [2, 1], frames: 2, fps: 1, start: 0 }"]), 8)
check(flat(px, 0) and flat(px, 1) and two_valued(px, 2),
      f"a 64x64 flipbook cell 16 px wide reads level 2: channels "
      f"{', '.join(f'{c} in {px[..., c].min()}..{px[..., c].max()}' for c in range(3))}")

# A sprite tilted 60 degrees out of the view plane (align: world, normal
# (0, sin 60, cos 60)): 64 px wide along the texture's u, 32 px along v.
# lambda is log2 of the larger of texels per pixel along screen x and y
# (64 / 64 and 64 / 32): 1, level 1. Red, striped on level 0 only, is flat;
# green, striped on level 1, is not (level 2 would flatten it).
px = inside(render("tilted", ["size: 2", "texture: bits.png", "align: world",
                              "normal: [0, 0.8660254037844386, 0.5]"]), 16)
g = px[..., 1]
check(flat(px, 0) and g.max() - g.min() >= 100,
      f"a sprite tilted 60 degrees (64 x 32 px) reads level 1: red "
      f"{px[..., 0].min()}..{px[..., 0].max()}, green {g.min()}..{g.max()}")

# A ribbon's level is worked out at each pixel from its texel steps. As in
# check_ribbon.py: a parent moves along +x at 1 m/s from x = -1.5 under an
# orthographic camera of 4 m over 200 px (50 px per metre), laying 30
# trail points a second; at t = 1.5 s its flat strip (sprite: square) runs
# 1.5 - 1/30 m = 73.3 px along x, u across the texture's 64 columns
# (0.87 texels a pixel), and `size` metres across y, v over its 64 rows.
# Across is then the larger: lambda = log2(64 / (50 size)).
RIBBON = """pfx: 1
duration: 2
fps: 10
seed: 3
camera: { position: [0, 0, 5], target: [0, 0, 0], ortho: 4 }
image: { size: [200, 200], background: "#000000ff", tonemap: none, dither: false }
emitters:
  head:
    bursts: [{ time: 0, count: 1 }]
    position: [-1.5, 0, 0]
    speed: 1
    direction: [1, 0, 0]
    spread: 0
    lifetime: 10
    size: 0.1
    color: "#ff000000"
    forces: []
    trail: { emit: ribbon, rate: 30 }
  ribbon:
    draw: ribbon
    sprite: square
    speed: 0
    lifetime: 3
    size: %s
    color: "#ffffff"
    texture: bits.png
    forces: []
"""


def ribbon_pixels(name, size):
    """The strip's pixels at t = 1.5 s, away from its ends and edges."""
    path = os.path.join(WORK, name + ".yaml")
    with open(path, "w") as f:
        f.write(RIBBON % size)
    out = os.path.join(WORK, name)
    subprocess.run([PFX, "render", path, "-o", out, "-q", "--frames", "15:15"], check=True)
    frame = np.asarray(Image.open(os.path.join(out, name + "_0015.png")).convert("RGBA"),
                       dtype=np.int64)
    half = 25 * size  # pixels either side of the centre line, row 100
    return frame[int(100 - half) + 2:int(100 + half) - 2, 100 - 70:100 - 4, :3]


for lam, stripes, what in [(1, 1, "level 1: red flat, green striped"),
                           (2, 2, "level 2: red and green flat, blue striped")]:
    px = ribbon_pixels(f"ribbon{lam}", 64 / 2 ** lam / 50)
    reach = np.abs(px[..., stripes] - 127.5).max()
    ok = all(flat(px, c) for c in range(stripes)) and reach >= 100
    check(ok, f"a ribbon {64 // 2 ** lam} px wide (lambda {lam}) reads {what}: "
              f"{', '.join(f'{c} in {px[..., c].min()}..{px[..., c].max()}' for c in range(3))}")
px = ribbon_pixels("ribbon1.5", 64 / 2 ** 1.5 / 50)
reach = np.abs(px[..., 1] - 127.5).max()
check(flat(px, 0) and 0.8 * 63.75 <= reach <= 63.75 + 1,
      f"a ribbon {64 / 2 ** 1.5:.1f} px wide (lambda 1.5) reads half level 1, half level 2: "
      f"red {px[..., 0].min()}..{px[..., 0].max()}, green within {reach:.1f} of 127.5 "
      f"(formula 63.8)")

sys.exit(1 if failures else 0)
