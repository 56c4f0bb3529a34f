#!/usr/bin/python3
"""Makes the flipbook textures the examples use, into effects/textures/:

  flame_sheet.png  4x4 cells of 64 px: a licking flame tongue that rises,
                   narrows and breaks into wisps over the 16 cells (white,
                   its shape in alpha, so the emitter's colour tints it)
  smoke_sheet.png  4x4 cells of 64 px: a billowing puff that swells and
                   thins over the 16 cells (white, shape in alpha)
  fire_sheet.png   4x4 cells of 128 px: a loop of flame tongues (grey, hot
                   core to cool tips, shape in alpha) whose noise scrolls
                   up one whole period over the 16 cells, so played with
                   flipbook `fps` it loops without a jump
  smoke_puffs.png  4x4 cells of 128 px: a cauliflower puff that billows,
                   swells and breaks up over the 16 cells (white, shape in
                   alpha); smoke_puffs_normal.png is its normal map (its
                   density as a height), for `lit: true` sprites that are
                   dark on the side away from the light
  spark_sheet.png  4x4 cells of 32 px: 16 glints, a hot streak along +y with
                   a ragged tail, each its own, for `align: velocity`
                   sparks with `start: random` (or a twinkle with `fps`)

  steel_plate.png  64 px: an opaque brushed steel plate with a bevelled
                   rim, for a target that particles strike (particle_gun)

  shock_ring.png   256 px: a shockwave's ring: a thin bright leading edge
                   near the rim with a soft glow trailing inwards, broken
                   up a little by noise along its circumference (white,
                   shape in alpha)
  stone_tile.png   128 px: opaque stone slabs in a 2x2 bond with dark
                   grout, tileable
  stone_rim.png    128 px: the same stone in a square frame (its border
                   5 % of the side, transparent inside): a basin's rim
                   coping seen from above
  stone_band.png   128 px: a band of the stone across the middle, 11.5 %
                   of the height, transparent above and below (a basin's
                   wall, 0.3 m of a 2.6 m sprite)
  stone_riser.png  128 px: the same with a band 40 % high (a stair riser,
                   0.4 m of a 1 m sprite)
  stone_stairs.png 256 px: the front of a flight of five steps in the
                   stone, 1 m treads and 0.4 m risers on a 5 m sprite
                   (sparks_steps), transparent above the steps
  These let examples draw solid surfaces with world-aligned sprites.

  swipe_streaks.png 256x64 px: a textured ribbon's strip (u, left to
                   right, from its head to its tail; v across it): fine
                   streaks along the length, solid at the head and
                   breaking into separate strands towards the tail, as
                   a sword swipe's trail (grey streaks, shape in alpha)

Every noise field is periodic (it tiles) across its image and is scrolled
by whole periods, so no cell shows a seam and looping sheets loop. Each
cell fades to zero before its border, so mipmaps do not bleed between
cells.

Cells run row by row from the top left, as every engine reads them. The
noise is seeded, so the files are the same on every run (the committed
copies are what the examples read; rerun this only to change them).
Needs python3-numpy and python3-pil.

usage: make_textures.py [OUT_DIR]
(tests/docs/run_textures.sh checks that it regenerates the committed files
byte for byte)"""
import os
import sys

import numpy as np
from PIL import Image

CELL, GRID = 64, 4


def value_noise(shape, period, rng):
    """Smooth value noise on a lattice of `period` cells across the image,
    periodic so the puff has no seam when it scrolls."""
    lattice = rng.random((period, period))
    h, w = shape
    y = np.arange(h)[:, None] * period / h
    x = np.arange(w)[None, :] * period / w
    y0, x0 = np.floor(y).astype(int), np.floor(x).astype(int)
    fy, fx = y - y0, x - x0
    fy, fx = fy * fy * (3 - 2 * fy), fx * fx * (3 - 2 * fx)
    y1, x1 = (y0 + 1) % period, (x0 + 1) % period
    y0, x0 = y0 % period, x0 % period
    a = lattice[y0, x0] * (1 - fx) + lattice[y0, x1] * fx
    b = lattice[y1, x0] * (1 - fx) + lattice[y1, x1] * fx
    return a * (1 - fy) + b * fy


def fbm(shape, rng, octaves=4, base=4):
    total, amp, norm = np.zeros(shape), 1.0, 0.0
    for o in range(octaves):
        total += amp * value_noise(shape, base << o, rng)
        norm += amp
        amp *= 0.5
    return total / norm


def sheet(cell_alpha, cell=CELL, last=GRID * GRID - 1):
    """A 4x4 sheet of white cells of `cell` px whose alpha is cell_alpha(t)
    for t from 0 to 1 (last: the cell index that is t = 1; 16 for a loop,
    whose cell 16 would be cell 0 again). cell_alpha may return (grey,
    alpha) instead of alpha alone."""
    img = np.zeros((cell * GRID, cell * GRID, 4), dtype=np.float64)
    for k in range(GRID * GRID):
        r, c = divmod(k, GRID)
        out = cell_alpha(k / last)
        grey, a = out if isinstance(out, tuple) else (1.0, out)
        block = img[r * cell:(r + 1) * cell, c * cell:(c + 1) * cell]
        block[..., :3] = np.clip(grey, 0, 1)[..., None] if np.ndim(grey) else grey
        block[..., 3] = np.clip(a, 0, 1)
    return img


def to_image(img):
    return Image.fromarray(np.round(img * 255).astype(np.uint8), "RGBA")


def smoothstep(e0, e1, x):
    t = np.clip((x - e0) / (e1 - e0), 0, 1)
    return t * t * (3 - 2 * t)


def stretch(field):
    """The field rescaled to span 0..1 (fbm crowds the middle)."""
    return (field - field.min()) / (field.max() - field.min())


def border(cell, margin=0.06):
    """1 inside the cell, falling to 0 over its outer `margin`."""
    u = np.linspace(0, 1, cell)
    e = smoothstep(0, margin, np.minimum(u, 1 - u))
    return e[:, None] * e[None, :]


def flame(rng):
    # Two noise fields scrolled upwards with the cell index: the flame's
    # edge wavers and its top breaks into separate licks.
    big = fbm((CELL * 4, CELL), rng, octaves=4, base=4)
    y, x = np.mgrid[0:CELL, 0:CELL] / (CELL - 1.0)
    y = 1.0 - y  # 0 at the bottom, 1 at the top

    def cell(t):
        shift = int(t * 3 * CELL)
        n = big[shift:shift + CELL][::-1]
        height = 0.92 - 0.3 * t
        # a teardrop: round at the base, narrowing to a tip, its centre line
        # and edge wavering with the noise more towards the top
        v = np.clip(y / height, 0, 1)
        half = 0.3 * (1 - 0.3 * t) * np.sqrt(np.clip(1 - v, 0, 1)) * np.clip(0.4 + 2.2 * v, 0, 1)
        centre = 0.5 + 0.18 * (n - 0.5) * v
        d = np.abs(x - centre) / np.maximum(half, 1e-3)
        body = np.clip(1 - d * d, 0, 1)
        breakup = np.clip(0.75 + (n - 0.5) * 2.5 - 0.9 * t * v, 0, 1)
        fade = np.clip(1.25 - 0.8 * t, 0, 1)
        base = np.clip(y * 10, 0, 1)
        return body * breakup * fade * base * (y < height)

    return to_image(sheet(cell))


def smoke(rng):
    field = fbm((CELL * 2, CELL * 2), rng, octaves=5, base=4)
    y, x = np.mgrid[0:CELL, 0:CELL] / (CELL - 1.0) * 2 - 1

    def cell(t):
        radius = 0.55 + 0.4 * t
        off = int(t * CELL)
        n = field[off:off + CELL, off:off + CELL]
        d2 = (x * x + y * y) / (radius * radius)
        falloff = np.clip(1 - d2, 0, 1) ** 1.5
        billow = np.clip((n - 0.3 + 0.25 * (1 - np.sqrt(np.clip(d2, 0, 1)))) * 2.2, 0, 1)
        return falloff * billow * (1.0 - 0.45 * t)

    return to_image(sheet(cell))


def fire(rng):
    """Flame tongues: a teardrop body, round and hot at the base, whose
    outline is warped sideways and eaten by noise that rises through it,
    more strongly with height, so its top splits into tongues that lick up
    and break off. Grey carries the heat (1 in the core, about 0.3 at the
    tips), so a tinting colour gets inner structure."""
    n = 128
    coarse = stretch(fbm((n * 2, n), rng, octaves=4, base=3))  # periodic in y over 2n
    fine = stretch(fbm((n * 2, n), rng, octaves=4, base=6))
    y, x = np.mgrid[0:n, 0:n] / (n - 1.0)
    y = 1.0 - y  # 0 at the bottom
    edge = border(n)

    def cell(t):
        # rise one whole period (2n rows) over the loop, so cell 16 = cell 0;
        # the fine noise rises twice as fast (two periods)
        s = int(round(t * 2 * n))
        rows = np.arange(n)[::-1]
        c = coarse[(rows - s) % (2 * n)]
        f = fine[(rows - 2 * s) % (2 * n)]
        v = np.clip((y - 0.04) / 0.9, 0, 1)
        warp = 0.3 * (c - 0.5) * v + 0.12 * (f - 0.5) * v
        half = 0.38 * np.sqrt(np.clip(v / 0.18, 0, 1)) * (1 - v) ** 0.9 + 0.01
        d = np.abs(x - 0.5 - warp) / half
        erode = (2.2 * v + 0.2) * (0.9 - 2.0 * (0.55 * c + 0.45 * f))
        body = 1 - d * d + erode - 0.25 * v
        alpha = smoothstep(0.0, 0.8, body) * smoothstep(0.0, 0.3, y)
        heat = smoothstep(0.0, 1.2, body) * (1 - 0.6 * v)
        return 0.3 + 0.7 * heat, alpha * edge

    return to_image(sheet(cell, n, GRID * GRID))


def puffs(rng):
    """A cauliflower puff: a sphere whose surface is pushed out by billows
    (ridged noise, so it reads as rounded lobes), that swells, thins and
    breaks up over the 16 cells. Returns the sheet and its normal map, made
    from the density as a height field (flat where the puff is not)."""
    n = 128
    lobes = stretch(fbm((n, n), rng, octaves=4, base=4))
    detail = stretch(fbm((n, n), rng, octaves=3, base=16))
    y, x = np.mgrid[0:n, 0:n] / (n - 1.0) * 2 - 1
    edge = border(n)
    heights = []

    def cell(t):
        r = 0.6 + 0.3 * t
        shift = int(round(t * n / 2))
        l = np.roll(lobes, (shift, shift // 2), (0, 1))
        d = np.sqrt(x * x + y * y) / r
        billow = 1 - np.abs(2 * l - 1)  # ridges where the noise crosses its middle
        dens = (1 - d * d) * 1.2 + 0.7 * (billow - 0.6) + 0.35 * (detail - 0.5) - 0.6 * t * (1 - detail)
        a = smoothstep(0.0, 0.9, dens) * (1 - 0.45 * t * t) * edge
        # broad shapes only: the dome and its lobes (fine noise would speckle the light)
        heights.append(np.where(dens > 0, np.sqrt(np.clip(1 - d * d, 0, 1)) + 0.35 * billow, 0))
        return 0.75 + 0.25 * smoothstep(0.0, 1.0, dens), a

    img = sheet(cell, n)
    normal = np.zeros_like(img)
    for k, h in enumerate(heights):
        r, c = divmod(k, GRID)
        gy, gx = np.gradient(h * 5.0)
        nx, ny, nz = -gx, gy, np.ones_like(h)  # +y up the image: rows grow downwards
        length = np.sqrt(nx * nx + ny * ny + nz * nz)
        block = normal[r * n:(r + 1) * n, c * n:(c + 1) * n]
        for i, comp in enumerate((nx, ny, nz)):
            block[..., i] = np.where(h > 0, (comp / length + 1) / 2, 0.5 + 0.5 * (i == 2))
        block[..., 3] = 1
    return to_image(img), to_image(normal)


def sparks(rng):
    """16 glints of 32 px, each a streak along +y (the top of the cell is
    the direction of motion): a white-hot head, a tail that thins and
    flickers, a slight bend, each drawn with its own random numbers."""
    n = 32
    y, x = np.mgrid[0:n, 0:n] / (n - 1.0) * 2 - 1
    y = -y  # +1 at the top
    edge = border(n, 0.1)
    params = [(rng.uniform(0.45, 0.85), rng.uniform(-0.15, 0.15), rng.uniform(0, 6.28),
               rng.uniform(6, 14)) for _ in range(GRID * GRID)]
    k = iter(range(GRID * GRID))

    def cell(t):
        head, bend, phase, freq = params[next(k)]
        v = (y + 1) / 2  # 0 at the tail end, 1 at the top
        cx = bend * (1 - v) ** 2
        width = 0.05 + 0.10 * v
        across = np.exp(-((x - cx) / width) ** 2)
        along = smoothstep(0.0, head, v) * smoothstep(1.0, 0.85, v)
        flicker = 0.75 + 0.25 * np.sin(freq * v + phase)
        core = np.exp(-(((x - cx) / 0.12) ** 2 + ((v - head) / 0.12) ** 2))
        a = np.clip(across * along * flicker + core, 0, 1) * edge
        return np.clip(0.6 + 0.4 * core + 0.3 * v, 0, 1), a

    return to_image(sheet(cell, n))


def steel(rng):
    """Brushed steel: noise stretched along x (the brushing), a rim one
    tenth wide, lighter on its top and left edges and darker on the
    others, as if lit from the upper left."""
    n = 64
    brush = stretch(fbm((n, n // 8), rng, octaves=3, base=2))
    brush = np.repeat(brush, 8, axis=1)  # long along x
    y, x = np.mgrid[0:n, 0:n] / (n - 1.0)
    grey = 0.42 + 0.12 * (brush - 0.5) + 0.08 * (0.5 - y)
    rim = np.minimum(np.minimum(x, 1 - x), np.minimum(y, 1 - y)) < 0.08
    lit = (x < 0.08) | (y < 0.08)
    grey = np.where(rim, np.where(lit & ~((x > 0.92) | (y > 0.92)), 0.62, 0.22), grey)
    img = np.ones((n, n, 4))
    img[..., :3] = grey[..., None]
    return to_image(img)


def shock_ring(rng):
    """A thin hot edge at radius 0.9 (a Gaussian 0.02 wide) over a glow
    that rises from radius 0.55 to the edge, both modulated by noise
    round the circle so the ring is not a perfect band."""
    n = 256
    y, x = (np.mgrid[0:n, 0:n] + 0.5) / n * 2 - 1
    r = np.sqrt(x * x + y * y)
    ang = (np.arctan2(y, x) / (2 * np.pi)) % 1.0
    wobble = stretch(fbm((1, 64), rng, octaves=3, base=4))[0]
    w = wobble[(ang * 64).astype(int) % 64]
    edge = np.exp(-((r - 0.9) / 0.02) ** 2)
    trail = smoothstep(0.55, 0.9, r) * (r < 0.9) * 0.35
    a = np.clip((edge + trail) * (0.6 + 0.4 * w), 0, 1) * (r < 0.97)
    img = np.ones((n, n, 4))
    img[..., 3] = a
    return to_image(img)


def swipe_streaks(rng):
    """Streaks along u: a noise field 64 rows across and 8 columns along,
    each row read with linear interpolation over the 256 px length (so a
    streak changes 32 times more slowly along the strip than across it).
    The alpha is 1 at the head (u = 0) and falls to the streaks alone, cut
    to strands by a threshold, at the tail; the grey keeps the streaks
    from head to tail so the strip is never flat."""
    h, w = 64, 256
    field = stretch(fbm((h, 64), rng, octaves=3, base=16))[:, :9]
    u = (np.arange(w) + 0.5) / w
    cols = np.arange(9) / 8.0
    streak = np.stack([np.interp(u, cols, row) for row in field])
    strands = smoothstep(0.35, 0.75, streak)
    a = (1 - u) ** 2 + (1 - (1 - u) ** 2) * strands
    img = np.ones((h, w, 4))
    img[..., :3] = (0.55 + 0.45 * streak)[..., None]
    img[..., 3] = np.clip(a, 0, 1)
    return to_image(img)


def stone(rng):
    """Stone slabs: two rows of two slabs each (a 2x2 bond, the second row
    offset by half a slab), each slab its own shade, speckled by noise,
    with a thin dark grout line between them; tileable (periodic)."""
    n = 128
    grain = stretch(fbm((n, n), rng, octaves=4, base=8))
    shade = rng.uniform(0.8, 1.05, size=(2, 3))
    y, x = np.mgrid[0:n, 0:n] / float(n)
    row = (y * 2).astype(int) % 2
    xs = (x + 0.25 * row) % 1.0
    col = (xs * 2).astype(int)
    base = shade[row, col] * (0.55 + 0.3 * grain)
    fy, fx = (y * 2) % 1.0, (xs * 2) % 1.0
    grout = np.minimum(np.minimum(fy, 1 - fy), np.minimum(fx, 1 - fx)) < 0.025
    return np.where(grout, 0.25, base)


def stone_images(rng):
    """The stone texture alone, as a frame, and as bands across the middle
    (11.5 % and 40 % of the height)."""
    grey = stone(rng)
    n = grey.shape[0]
    y, x = (np.mgrid[0:n, 0:n] + 0.5) / n

    def rgba(alpha):
        img = np.zeros((n, n, 4))
        img[..., :3] = grey[..., None] * np.array([1.0, 0.97, 0.92])
        img[..., 3] = alpha
        return to_image(img)

    edge = np.minimum(np.minimum(x, 1 - x), np.minimum(y, 1 - y))
    out = {"stone_tile.png": rgba(np.ones((n, n))), "stone_rim.png": rgba(edge < 0.05)}
    for name, frac in (("stone_band.png", 0.115), ("stone_riser.png", 0.4)):
        out[name] = rgba(np.abs(y - 0.5) < frac / 2)
    # five steps down to the right over the 5 m sprite: step k (0..4) spans
    # x in [k, k + 1) m and rises to 2 - 0.4 k m; rows run from the top
    big = np.tile(grey, (2, 2))
    m = big.shape[0]
    yy, xx = (np.mgrid[0:m, 0:m] + 0.5) / m * 5
    top = 2.0 - 0.4 * np.floor(xx)
    img = np.zeros((m, m, 4))
    img[..., :3] = big[..., None] * np.array([1.0, 0.97, 0.92])
    img[..., 3] = (5 - yy) < top
    out["stone_stairs.png"] = to_image(img)
    return out


def main(argv):
    here = os.path.dirname(os.path.abspath(__file__))
    out = argv[1] if len(argv) > 1 else os.path.join(here, "..", "effects", "textures")
    os.makedirs(out, exist_ok=True)
    flame(np.random.default_rng(11)).save(os.path.join(out, "flame_sheet.png"), optimize=True)
    smoke(np.random.default_rng(23)).save(os.path.join(out, "smoke_sheet.png"), optimize=True)
    fire(np.random.default_rng(31)).save(os.path.join(out, "fire_sheet.png"), optimize=True)
    sheet_img, normal_img = puffs(np.random.default_rng(37))
    sheet_img.save(os.path.join(out, "smoke_puffs.png"), optimize=True)
    normal_img.save(os.path.join(out, "smoke_puffs_normal.png"), optimize=True)
    sparks(np.random.default_rng(41)).save(os.path.join(out, "spark_sheet.png"), optimize=True)
    steel(np.random.default_rng(43)).save(os.path.join(out, "steel_plate.png"), optimize=True)
    shock_ring(np.random.default_rng(53)).save(os.path.join(out, "shock_ring.png"), optimize=True)
    for name, img in stone_images(np.random.default_rng(47)).items():
        img.save(os.path.join(out, name), optimize=True)
    swipe_streaks(np.random.default_rng(59)).save(os.path.join(out, "swipe_streaks.png"), optimize=True)


if __name__ == "__main__":
    main(sys.argv)
