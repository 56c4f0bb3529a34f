"""Pixel tests with known answers for `draw: ribbon`, through the command
line (`pfx render`). A parent particle moves along +x at 1 m/s under an
orthographic camera of 4 m over 200 px (50 px per metre) and lays a trail
of 30 points a second into a ribbon emitter; at t = 1.5 s its strip runs
from x = -1.5 + 1/30 m (the first point, at the parent's age 1/30 s) to
x = 0 (the parent). A point laid at x is -x seconds old.

usage: check_ribbon.py PFX WORKDIR"""
import hashlib
import sys

import numpy as np

from looklib import check, failures, render_effect, rgba

PFX, WORK = sys.argv[1], sys.argv[2]
PX_PER_M = 50.0


HEAD = """pfx: 1
duration: 2
fps: 10
seed: 3
camera: { position: [0, 0, 5], target: [0, 0, 0], ortho: 4 }
image: { size: [200, 200], background: "#000000ff" }
emitters:
"""

PARENT = """  {name}:
    bursts: [{bursts}]
    position: {position}
    speed: 1
    direction: [1, 0, 0]
    spread: 0
    lifetime: {life}
    size: 0.1
    color: "#ff000000"
    forces: []
    trail: {{ emit: {child}, rate: {rate} }}
"""

RIBBON = """  {name}:
    draw: ribbon
    sprite: {sprite}
    speed: 0
    lifetime: 3
    size: {size}
    color: {color}
    forces: []
"""


def parent(name="head", child="ribbon", bursts="{ time: 0, count: 1 }",
           position="[-1.5, 0, 0]", rate=30, life=10):
    return PARENT.format(name=name, child=child, bursts=bursts, position=position, rate=rate,
                         life=life)


def ribbon(name="ribbon", sprite="square", size=0.4, color='"#ffffff"'):
    return RIBBON.format(name=name, sprite=sprite, size=size, color=color)


def render(name, emitters, args=()):
    """Writes the effect, renders it, and returns {frame number: float array
    (H, W, 4) in 0..255} and the PNG bytes' digests."""
    out = name + "".join(a.replace(":", "-") for a in args)
    frames, digests = {}, {}
    for k, path in render_effect(PFX, WORK, name, HEAD + emitters, args, out).items():
        frames[k] = rgba(path)
        with open(path, "rb") as f:
            digests[k] = hashlib.sha256(f.read()).hexdigest()
    return frames, digests


def column(x):
    """The pixel column whose centre is nearest world x."""
    return int(np.floor(100 + x * PX_PER_M))


# ---- A flat strip (sprite: square): width, length, no gaps ----
frames, _ = render("flat", parent() + ribbon())
img = frames[15][:, :, 0]
lit = img > 127
cols = np.nonzero(lit.any(axis=0))[0]
first_x, last_x = -1.5 + 1 / 30, 0.0
check(abs(cols.min() - (100 + first_x * PX_PER_M)) <= 1 and
      abs(cols.max() + 1 - (100 + last_x * PX_PER_M)) <= 1,
      "flat: the strip runs from the first trail point to the parent, px %d..%d (expected "
      "%.1f..%.1f)" % (cols.min(), cols.max() + 1, 100 + first_x * PX_PER_M, 100))
inner = range(column(first_x) + 1, column(last_x) - 1)
widths = [int(lit[:, c].sum()) for c in inner]
check(all(abs(w - 0.4 * PX_PER_M) <= 1 for w in widths),
      "flat: width is size x px per metre = 20 px +- 1 at every column, got %d..%d"
      % (min(widths), max(widths)))
rows = [np.nonzero(lit[:, c])[0] for c in inner]
check(all(r.max() - r.min() + 1 == len(r) for r in rows),
      "flat: each column of the strip is one unbroken run of rows")
check(all(lit[99, c] and lit[100, c] for c in inner),
      "flat: connected, no gap pixel along its centre line (%d columns)" % len(inner))
check(abs(img[100, column(-0.7)] - 255) <= 1 and not lit[:, :column(first_x) - 1].any(),
      "flat: white additive inside (%d), black before the first point" % img[100, column(-0.7)])

# ---- The strip runs on to its live parent, and stops at the last point
# once the parent is dead. At 7 points a second the youngest point at 1.5 s
# is at x = -1.5 + 10/7 (px 96.4), the parent at x = 0 (px 100); a parent
# of 1 s life laid its last point at age 6/7 (x = -0.643, px 67.9) and died
# at x = -0.5 (px 75).
def extent(frame):
    cols = np.nonzero((frame[:, :, 0] > 127).any(axis=0))[0]
    return cols.min(), cols.max() + 1


frames, _ = render("head", parent(rate=7) + ribbon())
lo, hi = extent(frames[15])
check(abs(hi - 100) <= 1 and abs(lo - (100 + (-1.5 + 1 / 7) * PX_PER_M)) <= 1,
      "head: at 7 points/s the strip reaches the live parent at px 100, got %d..%d" % (lo, hi))
frames, _ = render("dead", parent(rate=7, life=1) + ribbon())
lo, hi = extent(frames[15])
check(abs(hi - (100 + (-1.5 + 6 / 7) * PX_PER_M)) <= 1,
      "head: after the parent dies the strip ends at its last point, px %.1f, got %d"
      % (100 + (-1.5 + 6 / 7) * PX_PER_M, hi))

# ---- Colour over life: red at birth to blue at 3 s, linear ----
frames, _ = render("colour", parent() + ribbon(color='["#ff0000", "#0000ff"]'))
img = frames[15]
for x in (-1.2, -0.75, -0.3):
    c = column(x)
    u = -(c + 0.5 - 100) / PX_PER_M / 3  # age of the pixel centre's point / lifetime
    want = (255 * (1 - u), 0, 255 * u)
    got = tuple(img[100, c, :3])
    check(all(abs(g - w) <= 3 for g, w in zip(got, want)),
          "colour: at x = %g m the strip is (1 - u, 0, u) x 255 with u = age / life = %.3f: "
          "want (%.0f, %.0f, %.0f), got (%.0f, %.0f, %.0f)" % ((x, u) + want + got))

# ---- The round cross-section: (1 - a^2)^2 across the half-width ----
frames, _ = render("soft", parent() + ribbon(sprite="round"))
img = frames[15][:, :, 0]
c = column(-0.7)
for row in (100, 103, 106, 108):
    a = (row + 0.5 - 100) / 10.0  # pixel centre over the 10 px half-width
    want = 255 * (1 - a * a) ** 2
    check(abs(img[row, c] - want) <= 3,
          "soft: across = %.2f gives (1 - a^2)^2 x 255 = %.0f, got %.0f" % (a, want, img[row, c]))
check(img[89, c] == 0 and img[110, c] == 0, "soft: nothing beyond the half-width")

# ---- One strip per parent: two parents are never joined ----
# The emitter moves from y = 0.5 to y = -0.5 between t = 0 and 0.5 s; one
# parent is born at each end. At 1.5 s the upper trail runs x = -1.5..0 at
# y = 0.5, the lower x = -1.5..-0.5 at y = -0.5; a strip joining them would
# cross y = 0.
frames, _ = render("two", parent(
    bursts="{ time: 0, count: 1 }, { time: 0.5, count: 1 }",
    position="[{ t: 0, value: [-1.5, 0.5, 0] }, { t: 0.5, value: [-1.5, -0.5, 0] }]")
    + ribbon(size=0.2))
img = frames[15][:, :, 0]
check(not (img[95:105, :] > 0).any(), "two parents: nothing between their strips")
check((img[74, column(-1.0):column(-0.1)] > 127).all() and
      (img[124, column(-1.0):column(-0.6)] > 127).all() and
      not (img[124, column(-0.4):] > 0).any(),
      "two parents: each strip where its parent went, the younger one shorter")

# ---- Determinism: reruns and --frames slices give the same bytes ----
_, whole = render("swipe", parent() + ribbon(sprite="round", size=0.3))
_, again = render("swipe", parent() + ribbon(sprite="round", size=0.3))
_, part = render("swipe", parent() + ribbon(sprite="round", size=0.3), ("--frames", "7:12"))
check(whole == again, "determinism: a rerun gives byte-identical frames")
check(all(part[k] == whole[k] for k in part) and len(part) == 6,
      "determinism: frames 7..12 rendered alone equal the full render's")

print("%d failure(s)" % len(failures))
sys.exit(1 if failures else 0)
