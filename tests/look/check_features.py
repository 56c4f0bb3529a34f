"""Known answers for the look features of issue 26, through the command
line (`pfx bake`, `pfx render`): a tangent emission's velocities at right
angles to the radius; a tapered ribbon's width falling to zero at its ends
and a texture along its length;
a vortex-driven stretched sprite elongated along its path; sprite variety
by default (random turns, random flipbook start cells); smoke that shades
itself (light: { shadows: true }).
Each scene states its formula beside it.

usage: check_features.py PFX WORKDIR"""
import csv
import math
import os
import subprocess
import sys

import numpy as np
from PIL import Image

from looklib import check, failures, render_effect, rgba, write_effect

PFX, WORK = sys.argv[1], sys.argv[2]


def write(name, text):
    return write_effect(WORK, name, text)


def bake(name, text):
    """The baked rows of frame 0, as dicts of floats (emitter kept)."""
    out = os.path.join(WORK, name + ".csv")
    subprocess.run([PFX, "bake", write(name, text), "-o", out, "-q"], check=True)
    rows = []
    with open(out, newline="") as f:
        for r in csv.DictReader(f):
            rows.append({k: (v if k == "emitter" else float(v)) for k, v in r.items()})
    return rows


def render(name, text, args=()):
    """{frame number: float array (H, W, 4) in 0..255}."""
    return {k: rgba(p) for k, p in render_effect(PFX, WORK, name, text, args).items()}


# ---- direction: tangent. A disc rim of radius 1 at (3, 1, -2) and one
# turned 90 degrees about X (its axis is then world +Z... -Y x: Y -> Z).
# At birth each velocity is speed x axis x (p - c) / |axis x (p - c)|:
# at right angles to the radius and the axis, counter-clockwise about it.
TANGENT = """pfx: 1
duration: 0.1
fps: 10
seed: 5
camera: { position: [0, 10, 0.001], target: [0, 0, 0], ortho: 4 }
image: { size: [64, 64] }
emitters:
  flat:
    shape: { type: disc, radius: 1 }
    position: [3, 1, -2]
    bursts: [{ time: 0, count: 200 }]
    direction: tangent
    speed: 2
    lifetime: 10
    forces: []
  turned:
    shape: { type: cylinder, radius: 0.5, height: 1 }
    position: [-1, 0, 0]
    rotation: [90, 0, 0]
    bursts: [{ time: 0, count: 200 }]
    direction: tangent
    speed: 3
    lifetime: 10
    forces: []
"""
rows = [r for r in bake("tangent", TANGENT) if r["frame"] == 0]
cases = {"flat": ((3, 1, -2), (0, 1, 0), 2.0), "turned": ((-1, 0, 0), (0, 0, 1), 3.0)}
for name, (c, axis, speed) in cases.items():
    worst = 0.0
    n = 0
    for r in (r for r in rows if r["emitter"] == name):
        d = np.array([r["x"], r["y"], r["z"]]) - c
        d -= np.dot(d, axis) * np.array(axis)  # from the axis, at the point's height
        want = np.cross(axis, d)
        want *= speed / np.linalg.norm(want)
        v = np.array([r["vx"], r["vy"], r["vz"]])
        worst = max(worst, float(np.abs(v - want).max()))
        n += 1
    check(n == 200 and worst < 1e-5,
          "tangent %s: %d velocities equal %g x axis x radius / |axis x radius| (normal to the "
          "radius and the axis), worst error %.2g m/s" % (name, n, speed, worst))

# ---- ribbon taper. As tests/look/check_ribbon.py: a parent moves along +x
# at 1 m/s from x = -1.5 under an orthographic camera of 4 m over 200 px (50
# px a metre) and lays 30 points a second; at 1.5 s its strip runs from the
# first point, x0 = -1.5 + 1/30, to the parent at x = 0: length L = -x0. A
# flat (square) white additive strip of size 0.4 m is 20 px wide; with
# taper [0.25, 0.5] its width at x is 20 min(1, -x / (0.25 L),
# (x - x0) / (0.5 L)) px and its brightness falls with the same factor.
RIBBON = """pfx: 1
duration: 2
fps: 10
seed: 3
camera: { position: [0, 0, 5], target: [0, 0, 0], ortho: 4 }
image: { size: [200, 200], background: "#000000ff" }
emitters:
  head:
    bursts: [{ time: 0, count: 1 }]
    position: [-1.5, 0, 0]
    speed: 1
    direction: [1, 0, 0]
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
    size: 0.4
    forces: []
%s
"""
x0 = -1.5 + 1 / 30
L = -x0


def factor(x):
    return max(0.0, min(1.0, -x / (0.25 * L), (x - x0) / (0.5 * L)))


img = render("taper", RIBBON % "    ribbon: { taper: [0.25, 0.5] }")[15][:, :, 0]
covered = img > 2  # any light at all: the strip's full width at that column
bad = []
for col in range(int(100 + x0 * 50) + 1, 99):
    x = (col + 0.5 - 100) / 50
    want = 20 * factor(x)
    got = int(covered[:, col].sum())
    if abs(got - want) > 1.6 and not (want < 4 and got <= 4):  # the 4 px footprint floor
        bad.append("x %.2f: %d px, expected %.1f" % (x, got, want))
check(not bad, "taper: covered width is 20 px x min(1, head / 0.25 L, tail / 0.5 L) at every "
      "column" + ("; " + ", ".join(bad[:4]) if bad else ""))
mid = int(100 + (x0 + 0.6 * L) * 50)
ends = [int(covered[:, c].sum()) for c in (int(100 + x0 * 50), 99)]
check(max(ends) <= 4 and abs(int(covered[:, mid].sum()) - 20) <= 1,
      "taper: the width falls to the footprint floor (<= 4 px) at both ends (%d, %d px) and is "
      "full (20 px) between them (%d px)" % (ends[0], ends[1], int(covered[:, mid].sum())))
q = int(100 + (x0 + 0.25 * L) * 50)  # half-way up the tail's ramp: brightness 0.5
check(abs(img[100, q] - 255 * factor((q + 0.5 - 100) / 50)) <= 3,
      "taper: brightness on the centre line follows the same factor (%.0f, expected %.0f)"
      % (img[100, q], 255 * factor((q + 0.5 - 100) / 50)))
plain = render("untapered", RIBBON % "")[15][:, :, 0]
check(int((plain > 2)[:, 99].sum()) >= 19, "taper: without it the head is full width")

# A textured ribbon spans its texture once along its length, u = 0 at the
# head: a sheet red on its left half and green on its right draws the
# strip red from the parent (x = 0) back to its middle, x = x0 / 2, and
# green from there to its tail.
sheet = np.zeros((8, 64, 4))
sheet[:, :, 3] = 255
sheet[:, :32, 0] = 255
sheet[:, 32:, 1] = 255
Image.fromarray(sheet.astype(np.uint8), "RGBA").save(os.path.join(WORK, "halves.png"))
img = render("textured", RIBBON % "    texture: halves.png")[15]
row = img[100]
reds = [c for c in range(200) if row[c, 0] > 127 and row[c, 1] < 64]
greens = [c for c in range(200) if row[c, 1] > 127 and row[c, 0] < 64]
mid = 100 + x0 / 2 * 50
check(reds and greens and abs(min(reds) - mid) <= 1.5 and abs(max(greens) + 1 - mid) <= 1.5 and
      max(reds) >= 97 and min(greens) <= int(100 + x0 * 50) + 1,
      "texture: the strip is green from its tail to px %d and red from px %d to the head "
      "(expected the change at px %.1f, the middle of its length)"
      % (max(greens or [0]) + 1, min(reds or [0]), mid))

# ---- What is drawn from motion includes what the vortex moves. One
# square sprite born still at radius 1 m from a vortex about +Y (strength
# 120 deg/s at the axis, radius 10 m, d 0: f(r) = r^4 - 2 r^2 + 1) is
# carried round at |v| = 120 pi / 180 f(0.1) m/s, which its velocity
# column does not hold. Seen from above (50 px a metre), align: velocity
# with stretch { length: 1, speed: 0.5 } draws it 0.4 m across the path and
# 0.4 + 0.5 |v| m along it (old: 0.4 m both ways, |v| = 0). A square
# sprite's falloff (1 - y^2)^2 covers sqrt(1 - sqrt(2 / 255)) of each
# half-side above 2 of 255.
VORTEX = """pfx: 1
duration: 1
fps: 10
seed: 2
camera: { position: [0, 10, 0], target: [0, 0, 0], up: [0, 0, -1], ortho: 4 }
image: { size: [200, 200], background: "#000000ff" }
forces:
  swirl: { type: vortex, center: [0, 0, 0], axis: [0, 1, 0], strength: 120, radius: 10, d: 0 }
emitters:
  leaf:
    position: [1, 0, 0]
    bursts: [{ time: 0, count: 1 }]
    speed: 0
    lifetime: 10
    size: 0.4
    sprite: square
    align: velocity
    stretch: { length: 1, speed: 0.5 }
"""
whole = render("vortex_whole", VORTEX)
sliced = render("vortex_slice", VORTEX, args=("--frames", "5:5", "--threads", "3"))
check(np.array_equal(whole[5], sliced[5]),
      "vortex: frame 5 alone with 3 threads gives the whole run's bytes")
speed = math.radians(120) * (0.1 ** 4 - 2 * 0.1 ** 2 + 1)
cover = math.sqrt(1 - math.sqrt(2 / 255))
want_along, want_across = (0.4 + 0.5 * speed) * 50 * cover, 0.4 * 50 * cover
for frame, img in sorted(whole.items()):
    if frame not in (0, 5):
        continue
    ys, xs = np.nonzero(img[:, :, 0] > 2)
    pts = np.stack([xs + 0.5, ys + 0.5], axis=1)
    radial = pts.mean(axis=0) - (100, 100)
    radial /= np.linalg.norm(radial)
    tangent = np.array([-radial[1], radial[0]])
    along = pts @ tangent
    across = pts @ radial
    got_along, got_across = along.max() - along.min() + 1, across.max() - across.min() + 1
    check(abs(got_along - want_along) <= 2.5 and abs(got_across - want_across) <= 2.5,
          "vortex frame %d: the stretched sprite is %.1f px along its path (expected %.1f) and "
          "%.1f px across it (expected %.1f): elongated %.2fx along the tangent"
          % (frame, got_along, want_along, got_across, want_across, got_along / got_across))

# ---- Sprite variety. 16 emitters of one still particle each on a 4 x 4
# grid (ortho 8 m over 256 px: 32 px a metre, 48 px apart), each a 1 m
# sprite of a texture that is a horizontal bar (opaque in its middle 8 of
# 32 rows). An alpha-blended texture facing the camera turns at random: the
# bars' angles (from the pixels' second moments) are spread over the half
# turn; with angle: 0 set, or blend: add, every bar is level.
def save_png(name, rgba):
    Image.fromarray(np.asarray(rgba, dtype=np.uint8), "RGBA").save(os.path.join(WORK, name))


bar = np.zeros((32, 32, 4))
bar[12:20, :, :] = 255
save_png("bar.png", bar)
quad = np.zeros((16, 16, 4))
quad[:, :, 3] = 255
quad[:8, :8, 0] = quad[:8, 8:, 1] = quad[8:, :8, 2] = 255  # red, green; blue, black
quad[8:, 8:, 3] = 255
save_png("cells.png", quad)
GRID = """pfx: 1
duration: 1
fps: 10
seed: 4
camera: { position: [0, 0, 5], target: [0, 0, 0], ortho: 8 }
image: { size: [256, 256], background: "#000000ff", dither: false }
emitters:
"""


def grid(extra):
    text = GRID
    for k in range(16):
        text += ("  e%d:\n    bursts: [{ time: 0, count: 1 }]\n    position: [%g, %g, 0]\n"
                 "    speed: 0\n    lifetime: 10\n    size: 1\n    forces: []\n%s"
                 % (k, -2.25 + 1.5 * (k % 4), -2.25 + 1.5 * (k // 4), extra))
    return text


def bar_angles(img):
    """The long axis of each grid cell's bar, degrees in [0, 180)."""
    out = []
    for k in range(16):
        cx, cy = 128 + 48 * (-1.5 + k % 4), 128 - 48 * (-1.5 + k // 4)
        w = img[int(cy) - 24:int(cy) + 24, int(cx) - 24:int(cx) + 24, 0]
        ys, xs = np.nonzero(w > 64)
        x, y = xs - xs.mean(), -(ys - ys.mean())
        c = np.cov(np.stack([x, y]))
        out.append(math.degrees(0.5 * math.atan2(2 * c[0, 1], c[0, 0] - c[1, 1])) % 180)
    return out


def level(a):
    return min(a, 180 - a)


turned = bar_angles(render("turned", grid("    texture: bar.png\n    blend: alpha\n"))[0])
gaps = np.diff(sorted(turned) + [min(turned) + 180])  # round the half turn
check(max(gaps) < 60 and sum(level(a) > 10 for a in turned) >= 12,
      "variety: 16 alpha-blended bars turn at random, angles %s deg (largest gap %.0f, "
      "expected < 60)" % (" ".join("%.0f" % a for a in turned), max(gaps)))
for name, extra in (("set", "    texture: bar.png\n    blend: alpha\n    angle: 0\n"),
                    ("additive", "    texture: bar.png\n    blend: add\n")):
    angles = bar_angles(render("bars_" + name, grid(extra))[0])
    check(max(level(a) for a in angles) < 1,
          "variety: with %s every bar is level (worst %.2f deg)"
          % ("angle: 0" if name == "set" else "blend: add", max(level(a) for a in angles)))

# A looping flipbook (fps) starts each particle at its own cell: at frame 0
# the 16 centres show more than one of the four cells; with start: 0, or a
# sheet over life, all show the first (red).
def cells(img):
    out = []
    for k in range(16):
        cx, cy = 128 + 48 * (-1.5 + k % 4), 128 - 48 * (-1.5 + k // 4)
        out.append(tuple(int(v > 127) for v in img[int(cy), int(cx), :3]))
    return out


for name, book, want_many in (("fps", "fps: 2", True), ("start0", "fps: 2, start: 0", False),
                              ("life", "over: life", False)):
    seen = cells(render("book_" + name, grid(
        "    texture: cells.png\n    blend: add\n    flipbook: { grid: [2, 2], %s }\n" % book))[0])
    red = sum(c == (1, 0, 0) for c in seen)
    check(len(set(seen)) >= 3 if want_many else red == 16,
          "variety: flipbook { %s }: %d distinct cells at birth, %d red%s"
          % (book, len(set(seen)), red, " (expected >= 3)" if want_many else " (expected 16)"))

# ---- Shadows. The light travels along +x. A caster puff (alpha 0.8, 1 m)
# at x = -1 and a lit receiver (0.6 m, alpha 0.02 so that its own depth is
# negligible, intensity 80) at x = +1, both at y = z = 0, under an
# orthographic camera on +z (3 m over 200 px). Along the receiver's centre
# row every fragment lies on the line through the caster's centre, where
# its optical depth is its alpha x f(0) = 0.8: the direct light (ambient
# 0) is exp(-0.8) = 0.449 of the unshadowed render's, pixel by pixel.
PAIR = """pfx: 1
duration: 1
fps: 10
seed: 7
camera: { position: [0, 0, 6], target: [0, 0, 0], ortho: 3 }
image: { size: [200, 200], background: "#000000ff", dither: false }
light: { direction: [1, 0, 0], ambient: [0, 0, 0], shadows: %s }
emitters:
  caster:
    position: [-1, 0, 0]
    bursts: [{ time: 0, count: 1 }]
    speed: 0
    lifetime: 10
    size: 1
    color: "#808080"
    alpha: 0.8
    blend: alpha
    forces: []
  receiver:
    position: [1, 0, 0]
    bursts: [{ time: 0, count: 1 }]
    speed: 0
    lifetime: 10
    size: 0.6
    alpha: 0.02
    intensity: 80
    blend: alpha
    lit: true
    forces: []
"""
shaded = render("pair_on", PAIR % "true", args=("--frames", "0:0"))[0][:, :, 0]
plain = render("pair_off", PAIR % "false", args=("--frames", "0:0"))[0][:, :, 0]
row = [c for c in range(200) if plain[99, c] > 40 and c > 100]
ratios = [shaded[99, c] / plain[99, c] for c in row]
check(len(row) >= 5 and all(abs(q - math.exp(-0.8)) <= 0.03 for q in ratios),
      "shadows: behind a puff of alpha 0.8 the lit receiver gets exp(-0.8) = 0.449 of the "
      "light on %d pixels of its centre row, got %.3f..%.3f"
      % (len(row), min(ratios or [0]), max(ratios or [0])))
half = render("pair_half", PAIR % "true, shadow_density: 0.5", args=("--frames", "0:0"))[0][:, :, 0]
ratios = [half[99, c] / plain[99, c] for c in row]
check(len(row) >= 5 and all(abs(q - math.exp(-0.4)) <= 0.03 for q in ratios),
      "shadows: shadow_density 0.5 halves the optical depth: exp(-0.4) = 0.670 of the light, "
      "got %.3f..%.3f" % (min(ratios or [0]), max(ratios or [0])))
check(np.array_equal(shaded[:, :90], plain[:, :90]),
      "shadows: the caster, which nothing shadows and which is not lit, is unchanged")

# A dense lit cloud lit from the left (+x travel): 400 puffs of alpha 0.5
# in a sphere of 0.8 m. With shadows its far (right) side is darker than
# its lit side by more than the spherical normals alone make it, and its
# middle is darker than without shadows.
CLOUD = """pfx: 1
duration: 1
fps: 10
seed: 7
camera: { position: [0, 0, 6], target: [0, 0, 0], ortho: 3 }
image: { size: [200, 200], background: "#000000ff", dither: false }
light: { direction: [1, 0, 0], ambient: [0.1, 0.1, 0.1], shadows: %s }
emitters:
  cloud:
    shape: { type: sphere, radius: 0.8 }
    bursts: [{ time: 0, count: 400 }]
    speed: 0
    lifetime: 10
    size: 0.5
    alpha: 0.5
    blend: alpha
    lit: true
    forces: []
"""
on = render("cloud_on", CLOUD % "true", args=("--frames", "0:0"))[0][:, :, 0]
off = render("cloud_off", CLOUD % "false", args=("--frames", "0:0"))[0][:, :, 0]


def sides(img):
    return img[80:120, 40:70].mean(), img[80:120, 85:115].mean(), img[80:120, 130:160].mean()


(lit_on, mid_on, far_on), (lit_off, mid_off, far_off) = sides(on), sides(off)
check(far_on / lit_on < 0.8 * far_off / lit_off and mid_on < 0.75 * mid_off,
      "shadows: cloud far/lit side %.1f/%.1f = %.2f (without shadows %.1f/%.1f = %.2f), middle "
      "%.1f (without %.1f)" % (far_on, lit_on, far_on / lit_on, far_off, lit_off,
                               far_off / lit_off, mid_on, mid_off))
again = render("cloud_again", CLOUD % "true", args=("--frames", "0:0", "--threads", "3"))[0]
check(np.array_equal(again[:, :, 0], on), "shadows: the same bytes on a rerun with 3 threads")
try:
    egl = render("cloud_egl", CLOUD % "true", args=("--frames", "0:0", "--renderer", "egl-cpu"))[0]
    check(np.array_equal(egl[:, :, 0], on), "shadows: egl-cpu gives osmesa's bytes")
except subprocess.CalledProcessError:
    print("ok   shadows: egl-cpu is not built here (skipped)")

sys.exit(1 if failures else 0)
