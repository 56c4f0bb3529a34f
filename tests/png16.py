"""16-bit RGBA PNG decoding in Python (zlib and numpy only), for the
motion-vector tests (tests/jobs/check_motion_vectors.py): Pillow opens a
16-bit RGBA PNG as 8-bit RGBA, dropping the low byte these tests check.
Handles colour type 6 at depth 16, non-interlaced, with any of the five
filters."""
import numpy as np

from png_rgba import read_image_data


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    return a if pa <= pb and pa <= pc else (b if pb <= pc else c)


def decode(path):
    """16-bit RGBA PNG -> numpy uint16 array of shape (height, width, 4)."""
    w, h, data = read_image_data(path, 16)
    raw = np.frombuffer(data, dtype=np.uint8)
    stride, bpp = 8 * w, 8
    rows = raw.reshape(h, stride + 1)
    out = np.zeros((h, stride), dtype=np.uint8)
    prev = np.zeros(stride, dtype=np.uint8)
    for y in range(h):
        ftype, line = rows[y, 0], rows[y, 1:].copy()
        if ftype == 2:
            line = line + prev  # uint8 wraps: mod 256
        elif ftype in (1, 3, 4):
            line = line.astype(np.int64)
            p = prev.astype(np.int64)
            for x in range(stride):
                a = line[x - bpp] if x >= bpp else 0
                c = p[x - bpp] if x >= bpp else 0
                pred = a if ftype == 1 else (a + p[x]) >> 1 if ftype == 3 else _paeth(a, p[x], c)
                line[x] = (line[x] + pred) & 255
            line = line.astype(np.uint8)
        elif ftype != 0:
            raise ValueError(f"{path}: bad filter type {ftype}")
        out[y] = line
        prev = line
    return out.view(">u2").reshape(h, w, 4).astype(np.uint16)
