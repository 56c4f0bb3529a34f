#!/usr/bin/python3
"""pfx beside Blender's legacy particle system, at equal accuracy.

Three scenes with exact solutions, built the same way in both programs:
  projectile  launched at (6, 8) m/s under g = 9.81, 2 s;
  drag        launched straight up at 20 m/s under g and quadratic drag
              c = 0.1 /m (a = -c |v| v, terminal speed 9.90 m/s), 3 s:
              closed form, tan while rising and log cosh while falling;
  bounce      dropped from rest at 2 m onto the plane y = 0 (Blender's
              z = 0) with restitution 0.5, no friction, 4 s: it comes to
              rest at t = sqrt(2 h / g) (1 + e) / (1 - e) = 1.916 s and stays
              on the plane.
Every particle of a scene starts in the same state (Blender: one emitter
vertex, all born on frame 1; pfx: a point burst at t = 0), so one particle
gives the accuracy of all of them. Output: 25 frames a second (Blender's
default physics timestep of 0.04 s a frame), every frame cached.

Accuracy: each setting runs once with 1 particle; its error is the largest
distance, over every frame, between the particle and the exact solution.
Blender's settings: integrator euler, verlet, midpoint, rk4 x subframes
0, 1, 3, 7, 15 (steps of 0.04 / (subframes + 1) s). pfx's: integrator auto
(sim.tolerance 1e-2 to 1e-6 m/s), exact, symplectic, verlet, midpoint, rk4,
euler x sim.rate 25, 50, 100, 200, 400. Blender's collision keeps particles
thickness_outer above the plane (set to its least, 0.001 m; they rest at
1.1 mm): that is part of its error on the bounce.

Equal accuracy: for each setting on Blender's front (no setting both faster
and at least as accurate; found from one timed run of every setting at the
first count; errors under 3e-5 m, float32 rounding, count as equal), the
target is its error; pfx's setting is the
fastest of the four with the fewest force evaluations whose error is at
most that. The ratio is Blender's time over pfx's, medians of --runs runs
at each particle count: each Blender bake is followed at once by the pfx
runs of its target, from inside the same Blender process, so that both
are timed under the same load; the ratio is the median of the runs'
ratios.

What is timed, on --threads cores (default 2; Blender -t N, pfx --threads N):
  Blender: time.perf_counter() around bpy.ops.ptcache.bake() inside
    Blender: its simulation of every frame, with the depsgraph update and
    the in-memory point-cache write of each frame; not its start-up, the
    scene set-up or reading the result back.
  pfx: `pfx bake -o - --frames 0:F:F` writes frame 0's and frame F's rows to
    a pipe; the time is the pause between the last bytes of frame 0 and the
    first of frame F, read on this side of the pipe: the simulation of
    every frame (with pfx's copy of the state for each frame) and the
    formatting of the first few rows of frame F; not its start-up, the
    compile, or the writing of the rows. A reader scheduled late can move
    the pause either way by up to a time slice on a loaded machine; hence
    the medians.
Blender's start-up and exit, and a whole pfx bake process, are printed
too.

Blender is not a dependency of pfx or its tests: this script runs outside
CI. Debian's Blender 3.4.1: `apt-get install -y blender`.

    tools/blender_compare.py [--pfx build/pfx] [--blender blender]
        [--counts 10000,100000] [--runs 3] [--threads 2]
        [--scenes projectile,drag,bounce] [--json OUT.json]

The same file is the script Blender runs (`blender -b --factory-startup
--python tools/blender_compare.py -- JOB.json`): it finds bpy there.
"""
import array
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

try:
    import bpy  # only inside Blender
except ImportError:
    bpy = None

G = 9.81
FPS = 25
SCENES = {
    "projectile": {"T": 2.0, "h0": 0.0, "v0": [6.0, 8.0], "drag": 0.0, "plane": False},
    "drag": {"T": 3.0, "h0": 0.0, "v0": [0.0, 20.0], "drag": 0.1, "plane": False},
    "bounce": {"T": 4.0, "h0": 2.0, "v0": [0.0, 0.0], "drag": 0.0, "plane": True, "e": 0.5},
}
BLENDER_INTEGRATORS = {"EULER": 1, "VERLET": 1, "MIDPOINT": 2, "RK4": 4}
BLENDER_SUBFRAMES = [0, 1, 3, 7, 15]
PFX_INTEGRATORS = {"exact": 1, "symplectic": 1, "euler": 1, "verlet": 2, "midpoint": 2, "rk4": 4}
PFX_RATES = [25, 50, 100, 200, 400]
PFX_TOLERANCES = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6]
# Errors under this are float32 rounding (positions are floats in both: 30
# ulps at 10 m) and count as equal.
ROUNDING = 3e-5


def frames_of(scene):
    return int(round(scene["T"] * FPS))


# ---------------------------------------------------------------- exact solutions
def exact(scene, t):
    """The exact (horizontal, vertical) position at time t."""
    h0, (vx, vy) = scene["h0"], scene["v0"]
    if scene["drag"]:
        c = scene["drag"]
        vt = math.sqrt(G / c)
        a = math.atan(vy / vt)
        ta = vt / G * a
        if t <= ta:
            return (0.0, h0 + vt * vt / G * math.log(math.cos(a - G * t / vt) / math.cos(a)))
        top = h0 + vt * vt / (2 * G) * math.log(1 + vy * vy / (vt * vt))
        return (0.0, top - vt * vt / G * math.log(math.cosh(G * (t - ta) / vt)))
    if scene["plane"]:
        e = scene["e"]
        t0 = math.sqrt(2 * h0 / G)
        if t <= t0:
            return (0.0, h0 - G * t * t / 2)
        u, start = e * G * t0, t0  # speed leaving the bounce, its time
        while u > 1e-12 and t > start + 2 * u / G:
            start += 2 * u / G
            u *= e
        if u <= 1e-12:
            return (0.0, 0.0)
        s = t - start
        return (0.0, max(0.0, u * s - G * s * s / 2))
    return (vx * t, h0 + vy * t - G * t * t / 2)


def error_of(scene, traj):
    """Largest distance from the exact solution over the frames traj[f]."""
    worst = 0.0
    for f, (x, y) in enumerate(traj):
        ex, ey = exact(scene, f / FPS)
        worst = max(worst, math.hypot(x - ex, y - ey))
    return worst


# ---------------------------------------------------------------- inside Blender
def blender_build(scene, n, integrator, subframes):
    """A fresh emitter (and ground plane) with Newtonian particles; returns
    the emitter object and its particle system."""
    sc = bpy.context.scene
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o, do_unlink=True)
    for block in (bpy.data.meshes, bpy.data.particles):
        for d in list(block):
            block.remove(d)
    me = bpy.data.meshes.new("emitter")
    me.from_pydata([(0.0, 0.0, scene["h0"])], [], [])
    ob = bpy.data.objects.new("emitter", me)
    sc.collection.objects.link(ob)
    if scene["plane"]:
        pm = bpy.data.meshes.new("ground")
        pm.from_pydata([(-100, -100, 0), (100, -100, 0), (100, 100, 0), (-100, 100, 0)], [],
                       [(0, 1, 2, 3)])
        po = bpy.data.objects.new("ground", pm)
        sc.collection.objects.link(po)
        po.modifiers.new("collision", "COLLISION")
        c = po.collision
        c.damping_factor = 1.0 - scene["e"]  # normal speed kept: 1 - damping
        c.damping_random = 0.0
        c.friction_factor = 0.0
        c.friction_random = 0.0
        c.thickness_outer = 0.001  # its least
        c.permeability = 0.0
        c.stickiness = 0.0
    ps = ob.modifiers.new("particles", "PARTICLE_SYSTEM").particle_system
    s = ps.settings
    s.count = n
    s.frame_start = s.frame_end = 1
    s.lifetime = 100000
    s.emit_from = "VERT"
    s.use_emit_random = False
    s.physics_type = "NEWTON"
    s.normal_factor = 0.0
    s.object_align_factor = (scene["v0"][0], 0.0, scene["v0"][1])
    s.factor_random = 0.0
    # Blender's air drag is force = -drag_factor size^2 |v| v, acceleration
    # force / mass: size 1 and mass 1 make drag_factor pfx's c.
    s.particle_size = 1.0
    s.size_random = 0.0
    s.mass = 1.0
    s.use_multiply_size_mass = False
    s.drag_factor = scene["drag"]
    s.integrator = integrator
    s.timestep = 1.0 / FPS
    s.subframes = subframes
    s.render_type = "NONE"
    s.display_method = "NONE"
    frames = frames_of(scene)
    sc.frame_start, sc.frame_end = 1, 1 + frames
    ps.point_cache.frame_start, ps.point_cache.frame_end = 1, 1 + frames
    sc.frame_set(1)
    return ob, ps


def blender_positions(ob, frame):
    """(horizontal, vertical) of every particle at a scene frame."""
    bpy.context.scene.frame_set(frame)
    dg = bpy.context.evaluated_depsgraph_get()
    pe = ob.evaluated_get(dg).particle_systems[0].particles
    loc = array.array("f", bytes(12 * len(pe)))
    pe.foreach_get("location", loc)
    return list(zip(loc[0::3], loc[2::3]))


def blender_job(job):
    """Runs job['runs'] (scene, n, integrator, subframes, all_frames) in
    turn, each bake followed at once by the pfx settings of its "pfx" list
    on the same scene (so that the two are timed seconds apart, under the
    same load), and prints one RESULT line of JSON."""
    start = time.perf_counter()
    out = []
    for r in job["runs"]:
        scene = SCENES[r["scene"]]
        ob, ps = blender_build(scene, r["n"], r["integrator"], r["subframes"])
        with bpy.context.temp_override(scene=bpy.context.scene, active_object=ob,
                                       point_cache=ps.point_cache):
            t0 = time.perf_counter()
            bpy.ops.ptcache.bake(bake=True)
            t1 = time.perf_counter()
        frames = frames_of(scene)
        res = dict(r, seconds=t1 - t0)
        if r["all_frames"]:
            res["traj"] = [blender_positions(ob, 1 + f)[0] for f in range(frames + 1)]
        else:
            last = blender_positions(ob, 1 + frames)
            ex = exact(scene, scene["T"])
            res["count"] = len(last)
            res["end_error"] = max(math.hypot(x - ex[0], y - ex[1]) for x, y in last)
        res["pfx"] = []
        for st in r.get("pfx", []):
            sim, whole, last = pfx_run(job["pfx_bin"], job["threads"], job["work"], "t", scene,
                                       r["n"], tuple(st), False)
            ex = exact(scene, scene["T"])
            res["pfx"].append({"setting": st, "sim": sim, "whole": whole, "count": len(last),
                               "end_error": max(math.hypot(x - ex[0], y - ex[1])
                                                for x, y in last)})
        out.append(res)
        with bpy.context.temp_override(scene=bpy.context.scene, active_object=ob,
                                       point_cache=ps.point_cache):
            bpy.ops.ptcache.free_bake()
    print("RESULT " + json.dumps({"runs": out, "job_s": time.perf_counter() - start}), flush=True)


# ---------------------------------------------------------------- pfx side
def pfx_effect(scene, n, integrator, rate, tolerance):
    frames = frames_of(scene)
    vx, vy = scene["v0"]
    speed = math.hypot(vx, vy)
    direction = [vx / speed, vy / speed, 0] if speed else [0, 1, 0]
    sim = "rate: %g, integrator: %s" % (rate, integrator)
    if tolerance:
        sim += ", tolerance: %g" % tolerance
    text = ("pfx: 1\nduration: %.17g\nfps: %d\nsim: { %s }\nforces:\n"
            "  g: { type: gravity, accel: [0, -%g, 0] }\n" % ((frames + 1) / FPS, FPS, sim, G))
    if scene["drag"]:
        text += "  air: { type: drag, c: %g }\n" % scene["drag"]
    if scene["plane"]:
        text += ("deflectors:\n  ground: { type: plane, point: [0, 0, 0], normal: [0, 1, 0], "
                 "resilience: %g, friction: 0 }\n" % scene["e"])
    text += ("emitters:\n  p:\n    shape: { type: point }\n    position: [0, %g, 0]\n"
             "    bursts: [{ time: 0, count: %d }]\n    direction: [%.17g, %.17g, 0]\n"
             "    speed: %.17g\n    lifetime: 1000\n" % (scene["h0"], n, direction[0],
                                                      direction[1], speed))
    return text


def pfx_rows(data, frame):
    """(horizontal, vertical) of every CSV row of a frame."""
    rows = []
    prefix = b"%d," % frame
    for line in data.split(b"\n")[1:]:
        if line.startswith(prefix):
            cols = line.split(b",")
            rows.append((float(cols[4]), float(cols[5])))
    return rows


def pfx_run(pfx, threads, work, name, scene, n, setting, all_frames):
    """One pfx bake of a setting: (simulation seconds, whole-process
    seconds, positions of the last frame, or every frame's of particle 0)."""
    integrator, rate, tolerance = setting
    path = os.path.join(work, name + ".yaml")
    with open(path, "w") as f:
        f.write(pfx_effect(scene, n, integrator, rate, tolerance))
    frames = frames_of(scene)
    cmd = [pfx, "bake", path, "-o", "-", "--format", "csv", "--threads", str(threads), "-q"]
    if not all_frames:
        cmd += ["--frames", "0:%d:%d" % (frames, frames)]
    start = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE)
    fd = p.stdout.fileno()
    chunks, stamps = [], []
    while True:
        b = os.read(fd, 1 << 20)
        stamps.append(time.perf_counter())
        if not b:
            break
        chunks.append(b)
    if p.wait() != 0:
        sys.exit("blender_compare: pfx bake failed on '%s'" % path)
    whole = time.perf_counter() - start
    data = b"".join(chunks)
    if all_frames:
        traj = [pfx_rows(data, f)[0] for f in range(frames + 1)]
        return None, whole, traj
    # The pause: the read that brought frame F's first byte, less the read
    # before it (frame 0's last bytes written before the simulation ran).
    at = data.index(b"\n%d," % frames) + 1
    seen = 0
    for i, b in enumerate(chunks):
        seen += len(b)
        if seen > at:
            break
    sim = stamps[i] - stamps[i - 1] if i > 0 else stamps[i] - start
    return sim, whole, pfx_rows(data, frames)


# ---------------------------------------------------------------- the driver
def run_blender(args, work, runs):
    """Blender's results for runs, and its start-up and exit in seconds
    (the process's wall time less the job's own)."""
    job = os.path.join(work, "job.json")
    with open(job, "w") as f:
        json.dump({"runs": runs, "pfx_bin": os.path.abspath(args.pfx), "threads": args.threads,
                   "work": work}, f)
    start = time.perf_counter()
    try:
        p = subprocess.run([args.blender, "-b", "--factory-startup", "-t", str(args.threads),
                            "--python", os.path.abspath(__file__), "--", job],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    except OSError as e:
        sys.exit("blender_compare: cannot run '%s': %s (Debian: apt-get install -y blender)" %
                 (args.blender, e.strerror))
    whole = time.perf_counter() - start
    for line in p.stdout.splitlines():
        if line.startswith("RESULT "):
            res = json.loads(line[7:])
            return res["runs"], whole - res["job_s"]
    sys.exit("blender_compare: blender failed:\n" + p.stdout[-3000:])


def pfx_settings():
    out = [("auto", FPS, tol) for tol in PFX_TOLERANCES]
    out += [(i, r, None) for i in PFX_INTEGRATORS for r in PFX_RATES]
    return out


def pfx_cost(setting):
    """Force evaluations a simulated second, to order the candidates."""
    integrator, rate, tolerance = setting
    if integrator == "auto":  # second order where it is not exact: substeps ~ tol^-1/2
        return rate * 2 * math.sqrt(1e-3 / tolerance)
    return rate * PFX_INTEGRATORS[integrator]


def name_of_pfx(setting):
    integrator, rate, tolerance = setting
    return "%s %g/s%s" % (integrator, rate, " tol %g" % tolerance if tolerance else "")


def front(points):
    """The settings no other is both cheaper and at least as accurate than
    (points: (cost, error, setting)), cheapest first."""
    out = []
    for p in sorted(points, key=lambda p: (p[0], p[1])):
        if not out or max(p[1], ROUNDING) < 0.9 * max(out[-1][1], ROUNDING):
            out.append(p)
    return out


def main():
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    src = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    ap.add_argument("--pfx", default=os.path.join(src, "build", "pfx"))
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--counts", default="10000,100000")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--scenes", default="projectile,drag,bounce")
    ap.add_argument("--json")
    args = ap.parse_args()
    counts = [int(float(c)) for c in args.counts.split(",")]
    report = {"threads": args.threads, "fps": FPS, "scenes": {}}
    with tempfile.TemporaryDirectory(prefix="pfx-blender-") as work:
        for sname in args.scenes.split(","):
            scene = SCENES[sname]
            # Accuracy: one particle, every frame.
            bl_runs = [{"scene": sname, "n": 1, "integrator": i, "subframes": s, "all_frames": True}
                       for i in BLENDER_INTEGRATORS for s in BLENDER_SUBFRAMES]
            bl_acc, _ = run_blender(args, work, bl_runs)
            bl_err = {(r["integrator"], r["subframes"]): error_of(scene, r["traj"]) for r in bl_acc}
            px_err = {}
            for k, st in enumerate(pfx_settings()):
                _, _, traj = pfx_run(args.pfx, args.threads, work, "acc%d" % k, scene, 1, st, True)
                px_err[st] = error_of(scene, traj)
            print("\n== %s: error (m, largest over %d frames) ==" % (sname, frames_of(scene) + 1))
            for (i, s), e in sorted(bl_err.items()):
                print("  blender %-8s subframes %2d  %.3g" % (i, s, e))
            for st, e in px_err.items():
                print("  pfx     %-26s %.3g" % (name_of_pfx(st), e))
            sc_report = report["scenes"][sname] = {
                "blender_error": {"%s/%d" % k: v for k, v in bl_err.items()},
                "pfx_error": {name_of_pfx(k): v for k, v in px_err.items()}, "counts": {}}
            for n in counts:
                if n == counts[0]:
                    # Blender's front, by its time at the first count (one run
                    # of every setting); then each front setting --runs times.
                    probe = [{"scene": sname, "n": n, "integrator": i, "subframes": s,
                              "all_frames": False} for i in BLENDER_INTEGRATORS
                             for s in BLENDER_SUBFRAMES]
                    res, _ = run_blender(args, work, probe)
                    pts = front([(r["seconds"], bl_err[(r["integrator"], r["subframes"])],
                                  (r["integrator"], r["subframes"])) for r in res])
                    targets = [p[2] for p in pts]
                # pfx candidates per target: the four cheapest (by force
                # evaluations) within the target's error (or rounding).
                cands = {}
                for t in targets:
                    ok = sorted((s for s in px_err if px_err[s] <= max(bl_err[t], ROUNDING)),
                                key=pfx_cost)
                    cands[t] = ok[:4]
                times_b = {t: [] for t in targets}
                times_p = {t: {} for t in targets}
                wholes_b, wholes_p = [], []
                ends_b, ends_p = {}, {}
                for _ in range(args.runs):
                    runs = [{"scene": sname, "n": n, "integrator": t[0], "subframes": t[1],
                             "all_frames": False, "pfx": cands[t]} for t in targets]
                    res, startup = run_blender(args, work, runs)
                    wholes_b.append(startup)
                    for r in res:
                        t = (r["integrator"], r["subframes"])
                        times_b[t].append(r["seconds"])
                        ends_b[t] = r["end_error"]
                        assert r["count"] == n, r["count"]
                        for q in r["pfx"]:
                            st = tuple(q["setting"])
                            assert q["count"] == n, q["count"]
                            ends_p[st] = q["end_error"]
                            times_p[t].setdefault(st, []).append(q["sim"])
                            wholes_p.append(q["whole"])
                rows = []
                print("\n== %s, %d particles, %d threads: medians of %d runs (ratio: the median "
                      "of the runs' ratios) ==" % (sname, n, args.threads, args.runs))
                print("  %-22s %10s %10s  %-26s %10s %10s %8s" %
                      ("blender", "error m", "s", "pfx", "error m", "s", "ratio"))
                for t in targets:
                    tb = statistics.median(times_b[t])
                    if not cands[t]:
                        print("  %-22s %10.3g %10.4f  no pfx setting reaches it" %
                              ("%s %d" % t, bl_err[t], tb))
                        continue
                    best = min(cands[t], key=lambda s: statistics.median(times_p[t][s]))
                    tp = statistics.median(times_p[t][best])
                    ratio = statistics.median(b / p for b, p in zip(times_b[t], times_p[t][best]))
                    rows.append({"blender": "%s subframes %d" % t, "blender_error": bl_err[t],
                                 "blender_end_error_n": ends_b[t], "blender_s": tb,
                                 "blender_runs_s": times_b[t], "pfx": name_of_pfx(best),
                                 "pfx_error": px_err[best], "pfx_end_error_n": ends_p[best],
                                 "pfx_s": tp, "pfx_runs_s": times_p[t][best], "ratio": ratio})
                    print("  %-22s %10.3g %10.4f  %-26s %10.3g %10.5f %7.0fx" %
                          ("%s %d" % t, bl_err[t], tb, name_of_pfx(best), px_err[best], tp,
                           ratio))
                print("  not timed above, medians: Blender's start-up and exit %.2f s a process; "
                      "a whole pfx bake process %.3f s" %
                      (statistics.median(wholes_b), statistics.median(wholes_p)))
                sc_report["counts"][str(n)] = {"rows": rows,
                                               "blender_startup_s": statistics.median(wholes_b),
                                               "pfx_whole_s": statistics.median(wholes_p)}
    if args.json:
        with open(args.json, "w") as f:
            json.dump(report, f, indent=1)


if __name__ == "__main__":
    if bpy is not None:
        blender_job(json.load(open(sys.argv[sys.argv.index("--") + 1])))
    else:
        main()
