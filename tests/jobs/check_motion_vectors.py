"""Motion-vector frames with known answers, through `pfx render
--motion-vectors`: single particles at a constant velocity under a
perspective camera, whose displacement per frame is worked out here from
the camera's fov and the image size; a particle turned by a vortex alone
(no velocity), whose displacement is the chord of its circle; one dying
between frames, extrapolated by its velocity; the scale as the 95th
percentile of the covered pixels with a few fast sparks over slow smoke;
an emitter left out with `motion_vectors: false`. The encoding is read
back by a decoder of our own (tests/png16.py: Pillow reads 16-bit RGBA as
8-bit).

usage: check_motion_vectors.py PFX WORKDIR SOURCE-DIR"""
import json
import math
import os
import subprocess
import sys

import numpy as np

PFX, WORK, SRC = sys.argv[1], sys.argv[2], sys.argv[3]
sys.path.insert(0, os.path.join(SRC, "tests"))
import png16  # noqa: E402

failures = []
W, H, FPS, FOV, DIST = 96, 64, 10, 40.0, 5.0
# A point on the plane z = 0 seen from (0, 0, 5) moves on screen by
# v dt x (H / 2) / tan(fov / 2) / distance pixels (gluPerspective; the
# horizontal scale is the same per pixel since aspect = W / H).
PX_PER_M = (H / 2) / math.tan(math.radians(FOV) / 2) / DIST


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


HEAD = f"""pfx: 1
duration: 1
fps: {FPS}
seed: 3
camera: {{ position: [0, 0, {DIST}], target: [0, 0, 0], fov: {FOV} }}
image: {{ size: [{W}, {H}], background: "#00000000" }}
emitters:
"""

ONE = """  {name}:
    bursts: [{{ time: 0, count: 1 }}]
    position: [{x}, {y}, 0]
    speed: {speed}
    direction: [{dx}, {dy}, 0]
    spread: 0
    lifetime: 10
    size: 0.6
    color: "{color}"
    blend: {blend}
    forces: {forces}
"""


def one(name="one", x=0.0, y=0.0, speed=1.2, d=(1, 0), color="#ffffffff", blend="alpha",
        forces="[]", lifetime=10, extra=""):
    text = ONE.format(name=name, x=x, y=y, speed=speed, dx=d[0], dy=d[1], color=color,
                      blend=blend, forces=forces)
    return text.replace("lifetime: 10", f"lifetime: {lifetime}") + extra


def render(name, emitters, *args, forces=""):
    path = os.path.join(WORK, name + ".yaml")
    with open(path, "w") as f:
        f.write(HEAD.replace("emitters:\n", forces + "emitters:\n") + emitters)
    out = os.path.join(WORK, name)
    subprocess.run([PFX, "render", path, "-o", out, "-q", "--motion-vectors", *args], check=True)
    frames = [png16.decode(os.path.join(out, f"{name}_mv_{k:04d}.png")) for k in range(FPS)]
    return out, frames


def decode(v, max_px, sign=1):
    return sign * (v.astype(np.float64) / 65535.0 - 0.5) * 2.0 * max_px


STEP = 1.2 / FPS * PX_PER_M  # px per frame at 1.2 m/s


def single(name, d, args, max_px, sign_y=1):
    """One particle moving along d: inside its footprint R and G decode to
    the displacement; outside, (0.5, 0.5, 0, 0)."""
    _, frames = render(name, one(x=-0.3 * d[0], y=-0.3 * d[1], d=d), *args)
    want = (STEP * d[0], STEP * d[1])
    bound = 2.0 * max_px / 65535  # one step of the 16-bit encoding
    worst, outside_bad, covered = 0.0, 0, 0
    for f in frames[:6]:
        cov = f[..., 3] > 0
        covered += int(cov.sum())
        ex = np.abs(decode(f[..., 0][cov], max_px) - want[0]).max()
        ey = np.abs(decode(f[..., 1][cov], max_px, sign_y) - want[1]).max()
        worst = max(worst, ex, ey)
        out = f[~cov]
        outside_bad += int(((out[:, 0] != 32768) | (out[:, 1] != 32768) | (out[:, 2] != 0)).sum())
        outside_bad += int((f[..., 2] != 0).sum())
    check(covered > 6 * 50 and worst <= bound,
          f"{name}: inside the footprint R, G decode to ({want[0]:.4f}, {want[1]:.4f}) px "
          f"within {worst:.2e} (bound {bound:.2e}, one 16-bit step)")
    check(outside_bad == 0, f"{name}: outside it (0.5, 0.5), A = 0, and B = 0 everywhere")
    return frames


f = single("right", (1, 0), ["--mv-max", "4"], 4.0)
cov = f[2][..., 3] > 0
check((f[2][..., 0][cov] > 32768).all() and (f[2][..., 1][cov] == 32768).all(),
      "moving right: R > 0.5 and G = 0.5 exactly")
check(f[2][..., 3].max() > 0.95 * 65535, f"coverage reaches {f[2][..., 3].max() / 65535:.3f} at the centre")
f = single("up", (0, 1), ["--mv-max", "4"], 4.0)
cov = f[2][..., 3] > 0
check((f[2][..., 1][cov] > 32768).all() and (f[2][..., 0][cov] == 32768).all(),
      "moving up: G > 0.5 (+G = up) and R = 0.5")
f = single("up_flipped", (0, 1), ["--mv-max", "4", "--mv-flip-y"], 4.0, sign_y=-1)
cov = f[2][..., 3] > 0
check((f[2][..., 1][cov] < 32768).all(), "moving up with --mv-flip-y: G < 0.5 (+G = down)")

# The scale from the sequence: every covered pixel moves by the one
# particle's displacement, so its percentile is that (the histogram returns
# a real sample), R is 1 inside it and the sidecar says max_px = STEP.
out, f = render("auto", one(x=-0.3))
meta = json.load(open(os.path.join(out, "auto_mv.json")))["motion_vectors"]
check(abs(meta["max_px"] - STEP) < 1e-6 * STEP and meta["g"].startswith("+y: up"),
      f"auto scale: max_px {meta['max_px']:.6f}, formula {STEP:.6f}")
cov = f[3][..., 3] > 0
check((f[3][..., 0][cov] >= 65534).all(), "auto scale: R is 1 inside the fastest particle")

# Additive: colour alpha 0, yet weighted by the sprite's shape.
f = single("additive", (1, 0), ["--mv-max", "4"], 4.0)[2]

# Two particles over each other, opposite velocities, equal alpha: their
# mean, 0.5 (no motion), wherever both are.
for blend in ("alpha", "add"):
    both = one("a", d=(1, 0), color="#ffffff80", blend=blend) + \
        one("b", d=(-1, 0), color="#ffffff80", blend=blend)
    _, f = render("pair_" + blend, both, "--mv-max", "4")
    cov = f[0][..., 3] > 0
    r = f[0][..., 0][cov].astype(int)
    check(cov.sum() > 50 and np.abs(r - 32768).max() <= 1,
          f"two {blend} particles with opposite velocities over each other: R = 0.5 "
          f"(off by at most {np.abs(r - 32768).max()} of 65535)")


# A vortex about the camera's axis turns a particle of no velocity 90
# degrees a second (its radius 1e6 m: the falloff is 1 to 1e-12 at 0.5 m):
# at fps 10 it goes 9 degrees a frame round a circle of 0.5 m, so from
# frame k to k + 1 it moves by the chord (cos, sin)(9 (k + 1)) - (cos,
# sin)(9 k) times 0.5 m, in pixels PX_PER_M a metre on the plane z = 0.
SPIN = "forces:\n  spin: { type: vortex, center: [0, 0, 0], axis: [0, 0, 1], strength: 90, " \
    "radius: 1000000 }\n"
R_SPIN, TURN = 0.5, math.radians(90 / FPS)


def chord(k):
    return (PX_PER_M * R_SPIN * (math.cos(TURN * (k + 1)) - math.cos(TURN * k)),
            PX_PER_M * R_SPIN * (math.sin(TURN * (k + 1)) - math.sin(TURN * k)))


_, f = render("vortex", one(x=R_SPIN, speed=0, forces="[spin]"), "--mv-max", "4", forces=SPIN)
bound = 2 * 2.0 * 4.0 / 65535  # two steps of the 16-bit encoding
worst, covered = 0.0, 0
for k, fr in enumerate(f):
    cov = fr[..., 3] > 0
    covered += int(cov.sum())
    want = chord(k)
    worst = max(worst, np.abs(decode(fr[..., 0][cov], 4.0) - want[0]).max(),
                np.abs(decode(fr[..., 1][cov], 4.0) - want[1]).max())
check(covered > FPS * 50 and worst <= bound,
      f"vortex alone (no velocity): every frame encodes the chord of its circle, "
      f"|d| = {math.hypot(*chord(0)):.4f} px, within {worst:.2e} px (bound {bound:.2e})")

# The same vortex on a particle moving at 1.2 m/s that dies at 0.45 s,
# between frames 4 and 5: frame 4 has no next position, so it encodes its
# velocity over a frame, (STEP, 0), while frame 3 (turned by the vortex)
# does not; frame 5 has nothing.
_, f = render("dying", one(x=0.2, speed=1.2, forces="[spin]", lifetime=0.45), "--mv-max", "4",
              forces=SPIN)
cov = f[4][..., 3] > 0
err = max(np.abs(decode(f[4][..., 0][cov], 4.0) - STEP).max(),
          np.abs(decode(f[4][..., 1][cov], 4.0)).max()) if cov.any() else 1e9
c3 = f[3][..., 3] > 0
off3 = max(abs(decode(f[3][..., 0][c3], 4.0).mean() - STEP), abs(decode(f[3][..., 1][c3], 4.0).mean()))
check(cov.sum() > 50 and err <= bound and off3 > 0.1 and not (f[5][..., 3] > 0).any(),
      f"a particle dying between frames 4 and 5 encodes its velocity over a frame at frame 4 "
      f"(off by {err:.2e} px), frame 3 the vortex's turn too (differs by {off3:.3f} px)")

# The scale from a few fast sparks over a lot of slow smoke: 200 smoke
# puffs at 0.2 m/s (0.02 m a frame), every one within the frame all along,
# cover some 22000 pixels a frame; the sparks at 30 m/s (3 m a frame) a few
# of the minimum footprint's 16 each, well under 5 %: the 95th percentile
# of the covered pixels is the smoke's displacement, and the sparks clip.
SMOKE_STEP = 0.2 / FPS * PX_PER_M
smoke = """  smoke:
    bursts: [{ time: 0, count: 200 }]
    shape: { type: box, size: [3, 1.5, 0] }
    speed: 0.2
    direction: [1, 0, 0]
    spread: 0
    lifetime: 10
    size: 0.6
    color: "#80808040"
    blend: alpha
    forces: []
  sparks:
    rate: 30
    position: [-2.5, 0, 0]
    speed: 30
    direction: [1, 0, 0]
    spread: 0
    lifetime: 0.2
    size: 0.05
    color: "#ffffffff"
    blend: add
    forces: []
"""
out, f = render("smoke_sparks", smoke)
meta = json.load(open(os.path.join(out, "smoke_sparks_mv.json")))["motion_vectors"]
check(abs(meta["max_px"] - SMOKE_STEP) <= 1e-3 * SMOKE_STEP and
      "95th percentile" in meta["max_from"],
      f"smoke and sparks: max_px {meta['max_px']:.6f}, the smoke's {SMOKE_STEP:.6f} px, "
      f"not the sparks' {30 / FPS * PX_PER_M:.1f} px")

# Either side of 5 %: the same smoke, 200 puffs of (0.6 m x PX_PER_M)^2
# pixels each in all 10 frames, 2000 footprints; and a burst of N puffs as
# large at 10 m/s, born at 0.45 s and dead at 0.55 s, so only frame 5 has
# them (extrapolated: 1 m, 17.58 px), all within the frame. They hold N /
# (2000 + N) of the covered pixels: 120 (5.7 %) make the 95th percentile
# theirs, 90 (4.3 %) leave it the smoke's.
BURST = """  burst:
    bursts: [{{ time: 0.45, count: {n} }}]
    shape: {{ type: box, size: [3, 1.5, 0] }}
    speed: 10
    direction: [1, 0, 0]
    spread: 0
    lifetime: 0.1
    size: 0.6
    color: "#80808040"
    blend: alpha
    forces: []
"""
for n, want, whose in ((120, 10 / FPS * PX_PER_M, "the burst's"), (90, SMOKE_STEP, "the smoke's")):
    name = f"burst_{n}"
    out, _ = render(name, smoke.split("  sparks:")[0] + BURST.format(n=n))
    got = json.load(open(os.path.join(out, name + "_mv.json")))["motion_vectors"]["max_px"]
    check(abs(got - want) <= 1e-3 * want,
          f"{n} fast puffs ({100 * n / (2000 + n):.1f} % of the covered pixels): max_px "
          f"{got:.5f}, {whose} {want:.5f} px")

# motion_vectors: false leaves an emitter out: a fast one at the top,
# drawn in colour, is "no motion, no coverage" in the pass and out of the
# scale, which is the other one's (moving up, at the bottom, below the
# middle row until frame 4).
both = one("left_out", y=0.8, speed=2.4, extra="    motion_vectors: false\n") + \
    one("kept", y=-0.8, d=(0, 1))
out, f = render("left_out", both)
meta = json.load(open(os.path.join(out, "left_out_mv.json")))["motion_vectors"]
from PIL import Image  # noqa: E402
top_bad = top_lit = 0
for k, fr in enumerate(f[:4]):
    colour = np.asarray(Image.open(os.path.join(out, f"left_out_{k:04d}.png")).convert("RGBA"))
    top_lit += int((colour[: H // 2, :, 3] > 0).sum())
    top = fr[: H // 2]
    top_bad += int(((top[..., 0] != 32768) | (top[..., 1] != 32768) | (top[..., 3] != 0)).sum())
cov = f[2][H // 2:, :, 3] > 0
up = decode(f[2][H // 2:, :, 1][cov], meta["max_px"])
check(top_lit > 100 and top_bad == 0 and abs(meta["max_px"] - STEP) < 1e-3 * STEP and
      cov.sum() > 50 and np.abs(up - STEP).max() <= 2 * 2 * STEP / 65535,
      f"motion_vectors: false: drawn in colour ({top_lit} pixels), (0.5, 0.5, A = 0) in the "
      f"pass ({top_bad} off), the scale the other emitter's ({meta['max_px']:.5f} px, "
      f"formula {STEP:.5f})")

sys.exit(1 if failures else 0)
