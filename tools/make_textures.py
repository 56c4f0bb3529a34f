#!/usr/bin/python3
"""Makes the flipbook textures the examples use, into effects/textures/:

  flame_sheet.png  4x4 cells of 64 px: a licking flame tongue that rises,
                   narrows and breaks into wisps over the 16 cells (white,
                   its shape in alpha, so the emitter's colour tints it)
  smoke_sheet.png  4x4 cells of 64 px: a billowing puff that swells and
                   thins over the 16 cells (white, shape in alpha)

Cells run row by row from the top left, as every engine reads them. The
noise is seeded, so the files are the same on every run (the committed
copies are what the examples read; rerun this only to change them).
Needs python3-numpy and python3-pil.

usage: make_textures.py [OUT_DIR]"""
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


def sheet(cell_alpha):
    img = np.zeros((CELL * GRID, CELL * GRID, 4), dtype=np.float64)
    for k in range(GRID * GRID):
        r, c = divmod(k, GRID)
        a = np.clip(cell_alpha(k / (GRID * GRID - 1)), 0, 1)
        block = img[r * CELL:(r + 1) * CELL, c * CELL:(c + 1) * CELL]
        block[..., :3] = 1.0
        block[..., 3] = a
    return Image.fromarray(np.round(img * 255).astype(np.uint8), "RGBA")


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

    return sheet(cell)


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

    return sheet(cell)


def main(argv):
    here = os.path.dirname(os.path.abspath(__file__))
    out = argv[1] if len(argv) > 1 else os.path.join(here, "..", "effects", "textures")
    os.makedirs(out, exist_ok=True)
    flame(np.random.default_rng(11)).save(os.path.join(out, "flame_sheet.png"), optimize=True)
    smoke(np.random.default_rng(23)).save(os.path.join(out, "smoke_sheet.png"), optimize=True)


if __name__ == "__main__":
    main(sys.argv)
