#!/usr/bin/python3
"""Checks `pfx tune`'s report against closed forms (tests/tune/run_tune.sh).

  check_tune.py errors SCENE DIR   each run's largest error (metres and
                                   pixels) against the integrator's own
                                   trajectory computed here and the exact
                                   motion
  check_tune.py files DIR          tune.csv and tune.json against their
                                   schema; tune.svg parsed: axes, legend,
                                   marks, tolerance line, Pareto front
  check_tune.py unstable DIR NAME RATE   NAME at RATE marked unstable,
                                   with the rule that predicted it
  check_tune.py within DIR TOL_M   the current setting is within TOL_M

Prints `ok   NAME` / `FAIL NAME: ...` lines (the harness counts them).
The scenes (run_tune.sh): one particle from t = 0, frames every 0.1 s to
T = 1.9 s, an orthographic camera 40 m tall over 400 px (10 px a metre)
looking along -Z, all motion in the XY plane and on the image.
"""
import csv
import json
import math
import sys
import xml.etree.ElementTree as ET

import jsonschema
import numpy as np

PX_PER_M = 10.0
FPS, FRAMES = 10, 20
REF_STEPS = 19 * 64  # the reference's steps to the last frame: 1.9 s at 640 /s
G, K_DRAG, V0, OMEGA, MU = 9.81, 2.0, 3.0, 2.0, 4.0


def ok(name):
    print("ok   " + name)


def fail(name, why):
    print("FAIL %s: %s" % (name, why))


def runs(d):
    with open(d + "/tune.csv", newline="") as f:
        return list(csv.DictReader(f))


# The acceleration of each scene at (x, v), 2-D.
def accel(scene, x, v):
    if scene == "projectile":
        return np.array([0.0, -G])
    if scene == "drag":
        return -K_DRAG * v
    if scene == "spring":
        return -OMEGA**2 * x
    if scene == "orbit":
        return -MU * x / np.linalg.norm(x) ** 3
    raise ValueError(scene)


def start(scene):
    if scene == "projectile":
        return np.array([0.0, 0.0]), np.array([V0, 0.0])
    if scene == "drag":
        return np.array([0.0, 0.0]), np.array([V0, 0.0])
    if scene == "spring":
        return np.array([1.0, 0.0]), np.array([0.0, 0.0])
    if scene == "orbit":
        return np.array([1.0, 0.0]), np.array([0.0, math.sqrt(MU)])


def exact(scene, t):
    if scene == "projectile":
        return np.array([V0 * t, -0.5 * G * t * t])
    if scene == "drag":
        return np.array([V0 * (1 - math.exp(-K_DRAG * t)) / K_DRAG, 0.0])
    if scene == "spring":
        return np.array([math.cos(OMEGA * t), 0.0])
    if scene == "orbit":  # circular: r = 1, angular speed sqrt(mu / r^3) = 2
        return np.array([math.cos(2 * t), math.sin(2 * t)])


# One step of each textbook scheme (x' = v, v' = a(x, v)).
def step(scheme, scene, x, v, h):
    a = lambda x, v: accel(scene, x, v)
    if scheme == "euler":
        return x + h * v, v + h * a(x, v)
    if scheme == "symplectic":
        v2 = v + h * a(x, v)
        return x + h * v2, v2
    if scheme == "midpoint":
        xm, vm = x + 0.5 * h * v, v + 0.5 * h * a(x, v)
        return x + h * vm, v + h * a(xm, vm)
    if scheme == "rk4":
        k1x, k1v = v, a(x, v)
        k2x, k2v = v + 0.5 * h * k1v, a(x + 0.5 * h * k1x, v + 0.5 * h * k1v)
        k3x, k3v = v + 0.5 * h * k2v, a(x + 0.5 * h * k2x, v + 0.5 * h * k2v)
        k4x, k4v = v + h * k3v, a(x + h * k3x, v + h * k3v)
        return (x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x),
                v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v))
    raise ValueError(scheme)


def expected_error(scheme, scene, h):
    """The largest distance, over the compared frames, between the
    scheme's trajectory at step h and the exact motion; and the rounding
    allowed: pfx keeps positions as 32-bit floats, so each step of the run
    and of the reference (rk4 at 8x the file's 80 steps/s) may round by an
    ulp (2^-24 relative, half an ulp each way) of the largest coordinate
    reached."""
    x, v = start(scene)
    steps = 0
    reach = 0.0
    per_frame = round(1 / (FPS * h))
    assert abs(per_frame * h * FPS - 1) < 1e-9, "steps must fall on frames"
    worst = 0.0
    for f in range(FRAMES):
        if f:
            for _ in range(per_frame):
                x, v = step(scheme, scene, x, v, h)
                steps += 1
        worst = max(worst, np.linalg.norm(x - exact(scene, f / FPS)))
        reach = max(reach, np.abs(exact(scene, f / FPS)).max())
    return worst, (steps + REF_STEPS) * reach * 2.0**-24


# Which integrators the closed forms cover per scene: the textbook schemes
# everywhere; on constant acceleration every second-order scheme and the
# closed form are exact.
SCHEMES = ["euler", "symplectic", "midpoint", "rk4"]
EXACT_ON_PROJECTILE = ["midpoint", "rk4", "verlet", "exact", "boris", "auto"]


def check_errors(scene, d):
    rows = [r for r in runs(d) if r["status"] == "ok" and r["reference"] == "0"]
    seen = {}
    for r in rows:
        name = r["integrator"]
        h = 1 / (float(r["rate"]) * max(1, int(r["substeps"])))
        got_m, got_px = float(r["err_max_m"]), float(r["err_max_px"])
        label = "%s %s at %s x %s" % (scene, name, r["rate"], r["substeps"])
        if scene == "projectile" and name in EXACT_ON_PROJECTILE:
            want, rounding = 0.0, (19 / (h * FPS) + REF_STEPS) * 17.8 * 2.0**-24
        elif name in SCHEMES:
            want, rounding = expected_error(name, scene, h)
        else:
            continue
        seen[name] = seen.get(name, 0) + 1
        # The reference is rk4 at 8x the rate, not the exact motion: it
        # differs from it by far less than these bounds.
        tol = 1e-4 * want + rounding
        if abs(got_m - want) > tol:
            fail(label, "largest error %.9g m, the closed form gives %.9g m" % (got_m, want))
        elif abs(got_px - PX_PER_M * got_m) > 1e-6 * got_px + 1e-8:
            fail(label, "%.9g px is not %g px a metre times %.9g m" % (got_px, PX_PER_M, got_m))
        elif r["fates"] != "0":
            fail(label, "%s particles' fate differs; there is one immortal particle" % r["fates"])
        else:
            ok("%s: %.6g m = closed form %.6g m" % (label, got_m, want))
    for name in ["euler", "symplectic"]:
        if seen.get(name, 0) < 7:
            fail(scene + " " + name, "fewer than two runs of it to compare (%d)" % seen.get(name, 0))


SCHEMA = {
    "type": "object",
    "required": ["effect", "tolerance", "metres_per_pixel", "converged", "current",
                 "reference", "recommended", "runs", "unstable", "scene_costs"],
    "properties": {
        "tolerance": {"type": "object", "required": ["px", "m", "given_in"],
                      "properties": {"px": {"type": "number", "exclusiveMinimum": 0},
                                     "m": {"type": "number", "exclusiveMinimum": 0},
                                     "given_in": {"enum": ["px", "m"]}}},
        "converged": {"type": "boolean"},
        "recommended": {"type": "integer", "minimum": -1},
        "runs": {"type": "array", "minItems": 3, "items": {
            "type": "object",
            "required": ["integrator", "rate", "substeps", "current", "reference", "recommended",
                         "status", "err_max_m", "err_p99_m", "err_max_px", "err_p99_px", "fates",
                         "compared", "seconds_per_sim_second", "particle_steps", "repeats", "why"],
            "properties": {
                "integrator": {"enum": ["auto", "euler", "symplectic", "midpoint", "rk4",
                                        "verlet", "exact", "boris"]},
                "rate": {"type": "number", "exclusiveMinimum": 0},
                "substeps": {"type": "integer", "minimum": 0},
                "status": {"enum": ["ok", "unstable", "not-applicable"]},
                "err_max_m": {"type": "number", "minimum": 0},
                "err_p99_m": {"type": "number", "minimum": 0},
                "seconds_per_sim_second": {"type": "number", "exclusiveMinimum": 0},
                "repeats": {"type": "integer", "minimum": 1}}}},
        "scene_costs": {"type": "array", "items": {
            "type": "object", "required": ["finding", "saving"]}},
    },
}


def check_files(d):
    doc = json.load(open(d + "/tune.json"))
    try:
        jsonschema.validate(doc, SCHEMA)
        ok("tune.json matches its schema")
    except jsonschema.ValidationError as e:
        fail("tune.json schema", e.message)
    rows = runs(d)
    if len(rows) != len(doc["runs"]):
        fail("tune.csv", "%d rows, tune.json has %d runs" % (len(rows), len(doc["runs"])))
    else:
        bad = [i for i, (r, j) in enumerate(zip(rows, doc["runs"]))
               if r["integrator"] != j["integrator"] or float(r["rate"]) != j["rate"]
               or abs(float(r["err_max_m"]) - j["err_max_m"]) > 1e-8 * (1 + j["err_max_m"])]
        (fail("tune.csv", "rows %s differ from tune.json" % bad) if bad
         else ok("tune.csv: %d rows, the same runs as tune.json" % len(rows)))
    ns = {"s": "http://www.w3.org/2000/svg"}
    svg = ET.parse(d + "/tune.svg").getroot()
    texts = ["".join(t.itertext()) for t in svg.iter("{http://www.w3.org/2000/svg}text")]
    for want in ["ms of wall time per simulated second", "largest position error, px",
                 "the file's setting"]:
        (ok("svg text '%s'" % want) if any(want in t for t in texts)
         else fail("svg text", "no '%s' among %s" % (want, texts[:12])))
    groups = {g.get("id"): g for g in svg.iter("{http://www.w3.org/2000/svg}g") if g.get("id")}
    tol = groups.get("tolerance")
    if tol is None or tol.find("s:polyline", ns) is None:
        fail("svg tolerance", "no tolerance line")
    else:
        pts = [tuple(map(float, p.split(","))) for p in tol.find("s:polyline", ns).get("points").split()]
        (ok("svg tolerance line is horizontal") if len(pts) == 2 and pts[0][1] == pts[1][1]
         else fail("svg tolerance", "points %s" % pts))
    plotted = {r["integrator"] for r in doc["runs"]
               if r["status"] == "ok" and not r["reference"] and not r["current"]}
    lines = {g.get("id")[5:] for g in svg.iter("{http://www.w3.org/2000/svg}g")
             if g.get("class") == "integrator"}
    legend = "".join(groups["legend"].itertext()) if "legend" in groups else ""
    (ok("svg: a line per integrator (%s), each in the legend" % ", ".join(sorted(lines)))
     if lines == plotted and all(n in legend for n in lines)
     else fail("svg lines", "lines %s, runs %s, legend '%s'" % (lines, plotted, legend)))
    marks = sum(len(g.findall("s:circle", ns)) for g in svg.iter("{http://www.w3.org/2000/svg}g")
                if g.get("class") == "integrator")
    n_ok = sum(1 for r in doc["runs"]
               if r["status"] == "ok" and not r["reference"] and not r["current"])
    (ok("svg: %d marks for %d runs" % (marks, n_ok)) if marks == n_ok
     else fail("svg marks", "%d marks for %d runs" % (marks, n_ok)))
    for gid in ["pareto", "current"]:
        (ok("svg group '%s'" % gid) if gid in groups and len(list(groups[gid])) > 0
         else fail("svg group", "'%s' missing or empty" % gid))


def check_unstable(d, name, rate):
    rows = [r for r in runs(d) if r["integrator"] == name and float(r["rate"]) == float(rate)]
    doc = json.load(open(d + "/tune.json"))
    if not rows or rows[0]["status"] != "unstable":
        fail("unstable %s" % name, "rows %s" % rows)
    elif "unstable" not in rows[0]["why"] and "stab" not in rows[0]["why"]:
        fail("unstable %s" % name, "no rule named in '%s'" % rows[0]["why"])
    elif name not in doc["unstable"]:
        fail("unstable %s" % name, "not in tune.json's unstable: %s" % doc["unstable"])
    else:
        ok("%s at %s steps/s marked unstable: %s; %s" % (name, rate, rows[0]["why"][:80],
                                                        doc["unstable"][name][:60]))


def check_within(d, tol_m):
    doc = json.load(open(d + "/tune.json"))
    cur = doc["runs"][doc["current"]]
    (ok("the recommendation applied: %.6g m within %s m" % (cur["err_max_m"], tol_m))
     if cur["status"] == "ok" and cur["err_max_m"] <= float(tol_m)
     else fail("recommendation applied", "current %s, recommended %d" % (cur, doc["recommended"])))


def check_costs(d, off_share, steps_scene):
    """off_share: the share of particle-frames off screen (None: no such
    finding expected); steps_scene: expect the steps-a-frame finding with
    the saving of the recommended rate over the file's."""
    doc = json.load(open(d + "/tune.json"))
    costs = doc["scene_costs"]
    off = [c for c in costs if "off screen" in c["finding"]]
    if off_share is None:
        (fail("costs", "unexpected %s" % off) if off else ok("no off-screen finding"))
    elif len(off) != 1 or abs(off[0]["saving"] - off_share) > 1e-12:
        fail("costs off screen", "expected a share of %s in %s" % (off_share, costs))
    else:
        ok("off screen for %s of its particle-frames: %s" % (off_share, off[0]["finding"]))
    sort = [c for c in costs if "depth sort" in c["finding"]]
    (ok("a depth sort that changes no pixel found") if sort
     else fail("costs sort", "no depth-sort finding in %s" % costs))
    if steps_scene:
        cur, rec = doc["runs"][doc["current"]], doc["runs"][doc["recommended"]]
        want = 1 - rec["rate"] * max(1, rec["substeps"]) / (cur["rate"] * max(1, cur["substeps"]))
        steps = [c for c in costs if "steps a frame" in c["finding"]]
        (ok("steps a frame beyond need: saves %.6g" % want)
         if len(steps) == 1 and abs(steps[0]["saving"] - want) < 1e-9
         else fail("costs steps", "expected a saving of %s in %s" % (want, costs)))


if __name__ == "__main__":
    kind = sys.argv[1]
    if kind == "errors":
        check_errors(sys.argv[2], sys.argv[3])
    elif kind == "files":
        check_files(sys.argv[2])
    elif kind == "unstable":
        check_unstable(sys.argv[2], sys.argv[3], sys.argv[4])
    elif kind == "costs":
        check_costs(sys.argv[2], None if sys.argv[3] == "none" else float(sys.argv[3]),
                    sys.argv[4] == "steps")
    elif kind == "within":
        check_within(sys.argv[2], sys.argv[3])
