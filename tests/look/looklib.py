"""What the look checks share: their ok and FAIL lines, and an effect
written, rendered with `pfx render` and read back with Pillow, as an
engine's importer reads the PNGs."""
import os
import subprocess

import numpy as np
from PIL import Image

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def write_effect(work, name, text):
    """WORK/NAME.yaml holding text; its path."""
    path = os.path.join(work, name + ".yaml")
    with open(path, "w") as f:
        f.write(text)
    return path


def render_effect(pfx, work, name, text, args=(), out=None):
    """Writes text as WORK/NAME.yaml, renders it into WORK/OUT (NAME when
    not given) with ARGS, and returns {frame number: PNG path}."""
    out = os.path.join(work, out or name)
    subprocess.run([pfx, "render", write_effect(work, name, text), "-o", out, "-q", *args],
                   check=True)
    return {int(n[-8:-4]): os.path.join(out, n) for n in sorted(os.listdir(out))
            if n.endswith(".png")}


def rgba(path, dtype=np.float64):
    """A PNG as an array (H, W, 4) of RGBA values in 0..255."""
    return np.asarray(Image.open(path).convert("RGBA"), dtype=dtype)
