"""Pixel tests with known answers for what a sprite looks like, through the
command line (`pfx render`): each scene is one or a few particles under an
orthographic camera of 2 m over 64 px (32 px per metre), and each check
compares pixels with a value worked out from the documented formula.

usage: check_look.py PFX WORKDIR"""
import os
import sys

import numpy as np
from PIL import Image

from looklib import check, failures, render_effect, rgba

PFX, WORK = sys.argv[1], sys.argv[2]
PX_PER_M = 32.0


HEAD = """pfx: 1
duration: {duration}
fps: {fps}
seed: 3
camera: {{ position: [0, 0, 5], target: [0, 0, 0], ortho: 2 }}
image: {{ size: [64, 64], background: "{background}"{image} }}
emitters:
"""


def render(name, emitters, fps=10, duration=1, background="#000000ff", image="", args=()):
    """Writes the effect, renders it, and returns its frames as float arrays
    (H, W, 4) in 0..255."""
    text = HEAD.format(duration=duration, fps=fps, background=background, image=image)
    frames = render_effect(PFX, WORK, name, text + emitters, args)
    return [rgba(frames[k]) for k in sorted(frames)]


def save_texture(name, cells):
    """A texture of solid 8x8 cells; cells[row][col] is an RGBA tuple, row 0
    at the top of the image."""
    rows, cols = len(cells), len(cells[0])
    img = Image.new("RGBA", (8 * cols, 8 * rows))
    for r in range(rows):
        for c in range(cols):
            img.paste(cells[r][c], (8 * c, 8 * r, 8 * c + 8, 8 * r + 8))
    img.save(os.path.join(WORK, name))


RED, GREEN, BLUE, WHITE = (255, 0, 0, 255), (0, 255, 0, 255), (0, 0, 255, 255), (255,) * 4
save_texture("quad.png", [[RED, GREEN], [BLUE, WHITE]])
save_texture("white.png", [[WHITE]])

ONE = """  one:
    bursts: [{{ time: 0, count: 1 }}]
    position: [{x}, 0, 0]
    speed: {speed}
    direction: [1, 0, 0]
    spread: 0
    lifetime: {lifetime}
    size: {size}
    color: {color}
    blend: {blend}
    forces: []
{extra}"""


def one(x=0, speed=0, lifetime=10, size=1, color='"#ffffffff"', blend="alpha", extra=""):
    return ONE.format(x=x, speed=speed, lifetime=lifetime, size=size, color=color, blend=blend,
                      extra=extra)


# Texture orientation: the PNG's top-left quadrant (red) is the sprite's
# top-left as seen on screen, the top-right green, and so on (at angle 0:
# an alpha-blended texture turns at random unless angle is set).
f = render("orientation", one(size=1, extra="    texture: quad.png\n    angle: 0\n"))[0]
for (x, y), want, name in [((24, 24), RED, "red"), ((40, 24), GREEN, "green"),
                           ((24, 40), BLUE, "blue"), ((40, 40), WHITE, "white")]:
    check(np.abs(f[y, x] - want).max() <= 1,
          f"texture orientation: pixel ({x}, {y}) is {name} {tuple(f[y, x].astype(int))}")

# Flipbook over life: four cells over a 1 s life, so ages 0.125, 0.375,
# 0.625 and 0.875 s (frames 1, 3, 5, 7 at 8 fps) are the middle of cells
# 0..3, read row by row from the top left.
frames = render("flipbook", one(size=1, lifetime=1, extra=(
    "    texture: quad.png\n"
    "    flipbook: { grid: [2, 2], frames: 4, over: life }\n")), fps=8)
for k, want, name in [(1, RED, "red"), (3, GREEN, "green"), (5, BLUE, "blue"),
                      (7, WHITE, "white")]:
    c = frames[k][32, 32]
    check(np.abs(c - want).max() <= 1,
          f"flipbook: frame {k} (age {k / 8:.3f} s) shows the {name} cell {tuple(c.astype(int))}")

# Flipbook at a rate: 2 cells per second, looping: ages 0.25 s and 0.75 s
# are the middle of cells 0 and 1, and 2.25 s is cell 0 again (4 frames
# played, frame 4 wraps to 0).
frames = render("flipbook_fps", one(size=1, lifetime=10, extra=(
    "    texture: quad.png\n"
    "    flipbook: { grid: [2, 2], frames: 4, fps: 2, start: 0 }\n")), fps=4, duration=3)
for k, want, name in [(1, RED, "red"), (3, GREEN, "green"), (5, BLUE, "blue"),
                      (7, WHITE, "white"), (9, RED, "red again")]:
    c = frames[k][32, 32]
    check(np.abs(c - want).max() <= 1,
          f"flipbook at 2 fps: age {k / 4} s shows the {name} cell {tuple(c.astype(int))}")


def extent(mask, axis):
    """Number of lit rows (axis 0) or columns (axis 1)."""
    return int(mask.any(axis=1 - axis).sum())


# Stretched sprite: size 0.25 m, stretch.length 1, stretch.speed 0.5 s,
# moving at 2 m/s along x: length 0.25 x 1 + 2 x 0.5 = 1.25 m = 40 px along
# x, width 0.25 m = 8 px along y.
frames = render("stretch", one(x=-0.5, speed=2, size=0.25, blend="add", extra=(
    "    texture: white.png\n"
    "    align: velocity\n"
    "    stretch: { length: 1, speed: 0.5 }\n")), fps=4)
lit = frames[1][..., 0] > 0  # t = 0.25 s: centred at x = 0
check(abs(extent(lit, 1) - 40) <= 1, f"stretch: lit length {extent(lit, 1)} px, formula 40 px")
check(abs(extent(lit, 0) - 8) <= 1, f"stretch: lit width {extent(lit, 0)} px, formula 8 px")

# Sub-pixel particles: 0.5 px wide (1/64 m) with colour 64 (HDR, so the
# quantisation to bytes is far below 5 %) drifting 0.1 px per frame: every
# frame's summed brightness is within 5 % of the sprite's area x colour.
frames = render("subpixel", one(x=-0.2, speed=0.1 / PX_PER_M * 30, size=1 / 64, blend="add",
                                color="[64, 64, 64]", extra="    sprite: square\n"),
                fps=30, image=", dither: false")
sums = [fr[..., 0].sum() / 255.0 for fr in frames]
# sprite: square falls off as (1 - x^2)^2 (1 - y^2)^2 over [-1, 1]^2, whose
# mean is (8/15)^2; area 0.25 px^2.
want = 64 * 0.25 * (8 / 15) ** 2
worst = max(abs(s / want - 1) for s in sums)
check(min(sums) > 0 and worst <= 0.05,
      f"sub-pixel: summed brightness {min(sums):.3f}..{max(sums):.3f}, "
      f"formula {want:.3f}, worst {100 * worst:.1f} %")

# Premultiplied = straight x alpha, on half-transparent alpha-blended
# particles over a transparent background.
SMOKE = """  smoke:
    rate: 200
    position: [0, -0.6, 0]
    direction: [0, 1, 0]
    spread: 0.4
    speed: [0.5, 1]
    lifetime: 2
    size: [0.2, 0.5]
    color: ["#80a0c080", "#f0c08040"]
    sprite: smoke
    blend: alpha
    forces: []
"""
straight = render("straight", SMOKE, background="#00000000", image=", dither: false",
                  args=("--alpha", "straight", "--frames", "9:9"))[0]
premul = render("premultiplied", SMOKE, background="#00000000", image=", dither: false",
                args=("--alpha", "premultiplied", "--frames", "9:9"))[0]
a = straight[..., 3:4]
diff = np.abs(premul[..., :3] - np.round(straight[..., :3] * a / 255.0)).max()
check((a > 0).sum() > 200 and diff <= 1 and np.array_equal(premul[..., 3], straight[..., 3]),
      f"premultiplied = straight x alpha within {diff:.0f}/255 over {(a > 0).sum()} pixels")

# Additive light in premultiplied output is colour with zero alpha.
glow = render("glow", one(size=1, blend="add", color='"#ff8000ff"',
                          extra="    texture: white.png\n"),
              background="#00000000", image=", alpha: premultiplied, dither: false")[0]
check(tuple(glow[32, 32].astype(int)) == (255, 128, 0, 0),
      f"premultiplied: additive light is colour with zero alpha {tuple(glow[32, 32].astype(int))}")

# The tone curve at a known pixel: colour 4 on black.
for image, want, what in [
        (", tonemap: reinhard", 4 / 5, "reinhard x / (1 + x) at x = 4"),
        (", tonemap: aces, exposure: -1",
         2 * (2.51 * 2 + 0.03) / (2 * (2.43 * 2 + 0.59) + 0.14), "aces at x = 4 x 2^-1"),
        (", tonemap: none", 1.0, "none clips at 1")]:
    f = render("tone", one(size=1, blend="add", color="[4, 4, 4]",
                           extra="    texture: white.png\n"), image=image + ", dither: false")[0]
    check(abs(f[32, 32, 0] - 255 * want) <= 0.5 + 1e-9,
          f"tonemap: {what}: {f[32, 32, 0]:.0f}, formula {255 * want:.2f}")


# preserve_hue: orange (1, 0.5, 0) at exposure 3 (8x) under ACES. Per
# channel it goes to yellow-white, (aces(8), aces(4), 0) ~ (1, 0.97, 0), a
# hue near 58 degrees; with preserve_hue 1 every channel is scaled by
# min(1, aces(8)) / 8, so the hue stays 30 degrees at every pixel of the
# sprite, its soft edge included; with 0.5 green is half way between.
def aces(x):
    return min(1.0, x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14))


def hue(rgb):
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return np.degrees(np.arctan2(np.sqrt(3) * (g - b), 2 * r - g - b)) % 360


ORANGE = dict(size=1.5, blend="add", color="[1, 0.5, 0]")
for k, want_g in [(1, 0.5), (0.5, aces(4) + 0.5 * (0.5 - aces(4))), (0, aces(4))]:
    flat = render("hue_flat", one(extra="    texture: white.png\n", **ORANGE),
                  image=f", tonemap: aces, exposure: 3, preserve_hue: {k}, dither: false")[0]
    got = tuple(flat[32, 32, :3].astype(int))
    check(got[0] == 255 and abs(got[1] - 255 * want_g) <= 0.5 + 1e-9 and got[2] == 0,
          f"preserve_hue {k}: orange at 8x is {got}, formula (255, {255 * want_g:.2f}, 0)")
soft = render("hue_soft", one(**ORANGE),
              image=", tonemap: aces, exposure: 3, preserve_hue: 1, dither: false")[0]
lit = soft[..., 0] >= 64
err = np.abs(hue(soft[..., :3])[lit] - 30).max()
check(lit.sum() > 500 and err <= 2,
      f"preserve_hue 1: {lit.sum()} px of a soft orange sprite at 8x within {err:.2f} deg of 30")
plain = render("hue_plain", one(**ORANGE), image=", tonemap: aces, exposure: 3, dither: false")[0]
check(hue(plain[32:33, 32, :3])[0] > 50,
      f"preserve_hue 0: the per-channel curve turns the core yellow, hue {hue(plain[32:33, 32, :3])[0]:.1f}")

# Motion blur: a 4 px sprite moving 3 m/s at 10 fps with the shutter open
# the whole interval sweeps |v| S / fps = 0.3 m = 9.6 px; its summed
# brightness is the unblurred sprite's.
MOVER = one(x=-0.5, speed=3, size=0.125, blend="add", extra="    texture: white.png\n")
sharp = render("sharp", MOVER, image=", dither: false")[3]
blur = render("blur", MOVER, image=", dither: false, motion_blur: { shutter: 1, samples: 16 }")
length = extent(blur[3][..., 0] > 0, 1)
check(abs(length - (4 + 9.6)) <= 1.5, f"motion blur: streak {length} px, formula 13.6 px")
s0, s1 = sharp[..., 0].sum(), blur[3][..., 0].sum()
check(abs(s1 / s0 - 1) <= 0.03, f"motion blur: brightness {s1 / s0:.4f} x the sharp frame's")
sliced = render("blur_slice", MOVER, image=", dither: false, motion_blur: { shutter: 1, samples: 16 }",
                args=("--frames", "3:3"))[0]
check(np.array_equal(sliced, blur[3]), "motion blur: --frames 3:3 gives frame 3's bytes")

if failures:
    print(f"{len(failures)} check(s) failed")
    sys.exit(1)
