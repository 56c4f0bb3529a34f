#!/usr/bin/python3
"""Checks `pfx bake` CSV output against exact solutions (run_physics.sh).

    check_bake.py CHECK CSV [key=value ...]

Each CHECK reads the baked rows, compares them with the closed-form answer
for the parameters given on the command line (the same numbers the test
wrote into the effect), prints the measured figures on one line and exits
0 when they are within tolerance, 1 when not. Standard library only.
"""
import csv
import math
import sys


def load(path):
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            for k in list(r):
                if k != "emitter":
                    r[k] = float(r[k])
            rows.append(r)
    return rows


def by_emitter(rows):
    out = {}
    for r in rows:
        out.setdefault(r["emitter"], []).append(r)
    for v in out.values():
        v.sort(key=lambda r: r["frame"])
    return out


def report(ok, text):
    print(("ok: " if ok else "FAILED: ") + text)
    return 0 if ok else 1


def sims_falloff(r, d):
    if not (0 <= r <= 1):
        return 0.0
    return (r ** 4 - 2 * r * r + 1) / (1 + d * r * r)


def check_vortex(rows, p):
    """Emitters named v<i> sit at radius p['r<i>'] from the Y axis; between
    frames fa and fb each turns by a f(r/R) (tb - ta) about it, and keeps
    its radius and height."""
    a = math.radians(p["a"])
    R, d = p["R"], p["d"]
    fa, fb = int(p["fa"]), int(p["fb"])
    worst_abs, worst_r, n = 0.0, 0.0, 0
    bad = []
    for name, rs in sorted(by_emitter(rows).items()):
        r0 = p["r" + name[1:]]
        at = {int(r["frame"]): r for r in rs}
        if fa not in at or fb not in at:
            bad.append("%s: frames %d/%d missing" % (name, fa, fb))
            continue
        A, B = at[fa], at[fb]
        th = math.atan2(B["z"], B["x"]) - math.atan2(A["z"], A["x"])
        th = -((th + math.pi) % (2 * math.pi) - math.pi)  # positive = counter-clockwise about +Y
        want = a * sims_falloff(r0 / R, d) * (B["time"] - A["time"])
        err = abs(th - want)
        rad_err = max(abs(math.hypot(X["x"], X["z"]) - r0) for X in (A, B))
        worst_abs = max(worst_abs, err)
        worst_r = max(worst_r, rad_err)
        n += 1
        # float32 positions: ~1e-7 m, so the angle is good to ~1e-6 rad
        if err > 2e-6 + 1e-5 * abs(want) or rad_err > 1e-5 or abs(B["y"] - A["y"]) > 1e-6:
            bad.append("%s r=%g: angle %.9g, expected %.9g (err %.3g), radius err %.3g"
                       % (name, r0, th, want, err, rad_err))
    if n < 3:
        bad.append("only %d emitters measured" % n)
    return report(not bad, "vortex: %d radii, max angle error %.3g rad, max radius drift %.3g m%s"
                  % (n, worst_abs, worst_r, "; " + "; ".join(bad) if bad else ""))


def circle_fit(pts):
    """Kasa least-squares circle through (x, y) points: centre and radius."""
    n = len(pts)
    mx = sum(p[0] for p in pts) / n
    my = sum(p[1] for p in pts) / n
    suu = svv = suv = suuu = svvv = suvv = svuu = 0.0
    for x, y in pts:
        u, v = x - mx, y - my
        suu += u * u
        svv += v * v
        suv += u * v
        suuu += u ** 3
        svvv += v ** 3
        suvv += u * v * v
        svuu += v * u * u
    b1 = 0.5 * (suuu + suvv)
    b2 = 0.5 * (svvv + svuu)
    det = suu * svv - suv * suv
    uc = (b1 * svv - b2 * suv) / det
    vc = (suu * b2 - suv * b1) / det
    r = math.sqrt(uc * uc + vc * vc + (suu + svv) / n)
    return mx + uc, my + vc, r


def linfit(xs, ys):
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    sxy = sum((x - mx) * (y - my) for x, y in zip(xs, ys))
    return sxy / sxx, my - sxy / sxx * mx


def check_lorentz(rows, p):
    """Emitters 'pos' (charge +q) and 'neg' (-q), mass m, launched at the
    origin along +X at speed v in B = (0, 0, B): circles of radius
    m v / (|q| B) centred at (0, -+r), period 2 pi m / (|q| B), |v| kept."""
    q, m, v, B = p["q"], p["m"], p["v"], p["B"]
    r_want = m * v / (abs(q) * B)
    T_want = 2 * math.pi * m / (abs(q) * B)
    em = by_emitter(rows)
    bad, figs = [], []
    for name, sign in (("pos", 1), ("neg", -1)):
        rs = em.get(name, [])
        if len(rs) < 20:
            bad.append("%s: %d rows" % (name, len(rs)))
            continue
        cx, cy, r = circle_fit([(r_["x"], r_["y"]) for r_ in rs])
        # centre: the force q v x B on +X velocity points along -sign Y
        c_err = math.hypot(cx - 0, cy - (-sign * r_want))
        ts, ph, prev, off = [], [], None, 0.0
        for r_ in rs:
            a = math.atan2(r_["y"] - cy, r_["x"] - cx)
            if prev is not None:
                while a + off - prev > math.pi:
                    off -= 2 * math.pi
                while a + off - prev < -math.pi:
                    off += 2 * math.pi
            prev = a + off
            ts.append(r_["time"])
            ph.append(prev)
        w, _ = linfit(ts, ph)
        T = 2 * math.pi / abs(w)
        sp = [math.sqrt(r_["vx"] ** 2 + r_["vy"] ** 2 + r_["vz"] ** 2) for r_ in rs]
        dv = max(abs(s / v - 1) for s in sp)
        zmax = max(abs(r_["z"]) for r_ in rs)
        # sense: positive charge turns clockwise seen from +Z (w < 0)
        sense_ok = (w < 0) == (sign > 0)
        figs.append("%s: radius %.7g (want %.7g, rel %.2g), period %.7g (want %.7g, rel %.2g), "
                    "centre (%.4g, %.4g) (want (0, %.4g)), max | |v|/v0 - 1 | %.2g"
                    % (name, r, r_want, abs(r / r_want - 1), T, T_want, abs(T / T_want - 1),
                       cx, cy, -sign * r_want, dv))
        if abs(r / r_want - 1) > 1e-3:
            bad.append("%s radius" % name)
        if abs(T / T_want - 1) > 1e-3:
            bad.append("%s period" % name)
        if c_err > 1e-3 * r_want or not sense_ok:
            bad.append("%s turns the wrong way (centre (%.4g, %.4g), expected (0, %.4g))"
                       % (name, cx, cy, -sign * r_want))
        if dv > 1e-4:
            bad.append("%s |v| drift %.3g" % (name, dv))
        if zmax > 1e-6:
            bad.append("%s left the plane z = 0 (%.3g)" % (name, zmax))
    return report(not bad, "lorentz: " + "; ".join(figs) + ("; BAD: " + ", ".join(bad) if bad else ""))


def check_orbit(rows, p):
    """One particle on a circular orbit of radius r about the origin for
    at least `orbits` periods: |x| stays r."""
    r0, mu = p["r"], p["mu"]
    T = 2 * math.pi * math.sqrt(r0 ** 3 / mu)
    rs = rows
    if not rs:
        return report(False, "orbit: no rows")
    span = rs[-1]["time"] - rs[0]["time"]
    dev = max(abs(math.sqrt(r_["x"] ** 2 + r_["y"] ** 2 + r_["z"] ** 2) / r0 - 1) for r_ in rs)
    sp = max(abs(math.sqrt(r_["vx"] ** 2 + r_["vy"] ** 2 + r_["vz"] ** 2) / math.sqrt(mu / r0) - 1)
             for r_ in rs)
    orbits = span / T
    ok = dev <= 1e-3 and orbits >= p["orbits"]
    return report(ok, "attractor: %.2f orbits of T = %.6g s, max | r/r0 - 1 | = %.3g, max | v/v_c - 1 | = %.3g"
                  % (orbits, T, dev, sp))


def worst_error_rate(rows, exact):
    """The largest position error over age (m per simulated second, the
    unit of sim.tolerance) over every row after birth, against exact(age)
    -> (x, y, z)."""
    worst, at = 0.0, 0.0
    for r in rows:
        if r["age"] <= 0:
            continue
        x, y, z = exact(r["age"])
        e = math.sqrt((r["x"] - x) ** 2 + (r["y"] - y) ** 2 + (r["z"] - z) ** 2) / r["age"]
        if e > worst:
            worst, at = e, r["age"]
    return worst, at


def kepler_position(t, mu, a, ecc):
    """Kepler orbit from pericentre a (1 - e) on +X moving along +Y: the mean
    anomaly n t, n = sqrt(mu / a^3), Kepler's equation by Newton."""
    M = math.sqrt(mu / a ** 3) * t
    E = M + ecc * math.sin(M)
    for _ in range(60):
        d = (E - ecc * math.sin(E) - M) / (1 - ecc * math.cos(E))
        E -= d
        if abs(d) < 1e-15:
            break
    return a * (math.cos(E) - ecc), a * math.sqrt(1 - ecc * ecc) * math.sin(E), 0.0


def check_tolerance(name, rows, p, exact):
    if not rows:
        return report(False, "%s: no rows" % name)
    worst, at = worst_error_rate(rows, exact)
    return report(worst <= p["tol"], "%s: largest error / age %.3g m/s (at age %.3g s), tolerance %g"
                  % (name, worst, at, p["tol"]))


def check_kepler(rows, p):
    """An unsoftened attractor's e = ecc orbit of semi-major axis a, from its
    pericentre: the error per second stays within tol."""
    return check_tolerance("kepler", rows, p, lambda t: kepler_position(t, p["mu"], p["a"], p["ecc"]))


def check_quadfall(rows, p):
    """A fall from rest under gravity g and quadratic drag c: v_t = sqrt(g/c),
    y = -(v_t^2 / g) ln cosh(g t / v_t)."""
    g, c = p["g"], p["c"]
    vt = math.sqrt(g / c)
    return check_tolerance("quadratic fall", rows, p,
                           lambda t: (0.0, -(vt * vt / g) * math.log(math.cosh(g * t / vt)), 0.0))


def check_magdrag(rows, p):
    """A charge (q/m = qm) in B along Z under gravity -g along Y and
    quadratic drag c from v0 = (u, 0, w): no closed form, so the reference is
    classical RK4 at h = 1e-4 s (its error, some h^4, is far below tol)."""
    qm, B, g, c = p["qm"], p["B"], p["g"], p["c"]

    def acc(v):
        s = math.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
        return (qm * v[1] * B - c * s * v[0], -qm * v[0] * B - g - c * s * v[1], -c * s * v[2])

    h, x, v, t = 1e-4, [0.0, 0.0, 0.0], [p["u"], 0.0, p["w"]], 0.0
    ref = {0: (0.0, 0.0, 0.0)}
    ages = sorted({round(r["age"], 6) for r in rows if r["age"] > 0})
    for age in ages:
        n = int(round((age - t) / h))
        for _ in range(n):
            k1v = acc(v)
            k1x = v
            v2 = [v[i] + 0.5 * h * k1v[i] for i in range(3)]
            k2v, k2x = acc(v2), v2
            v3 = [v[i] + 0.5 * h * k2v[i] for i in range(3)]
            k3v, k3x = acc(v3), v3
            v4 = [v[i] + h * k3v[i] for i in range(3)]
            k4v, k4x = acc(v4), v4
            x = [x[i] + h / 6 * (k1x[i] + 2 * k2x[i] + 2 * k3x[i] + k4x[i]) for i in range(3)]
            v = [v[i] + h / 6 * (k1v[i] + 2 * k2v[i] + 2 * k3v[i] + k4v[i]) for i in range(3)]
        t += n * h
        ref[age] = tuple(x)
    return check_tolerance("magnetic + quadratic drag", rows, p, lambda a: ref[round(a, 6)])


def check_same_response(rows, p):
    """The same effect baked at another sim.rate (the CSV `other`): a
    particle's random resilience and friction belong to it and its hit
    number, so each id's velocity in flight after its bounces is the same
    at both rates (gravity and the hit times are exact: float rounding
    apart), up to age `until`; and the draws do vary, over the range: the horizontal
    speed kept by the first bounce, (1 - mu), spans most of [1 - mu_hi, 1]."""
    other = {}
    for r in load(p["other"]):
        other[(r["frame"], r["id"])] = r
    worst, compared = 0.0, 0
    for r in rows:
        if r["age"] > p["until"]:
            continue
        o = other.get((r["frame"], r["id"]))
        if o is None:
            return report(False, "same response: id %d missing at frame %d of the other rate"
                          % (r["id"], r["frame"]))
        if r["y"] < 1e-3 or o["y"] < 1e-3:
            continue  # resting or sliding: when a bounce ends in rest depends on the step
        worst = max(worst, math.sqrt(sum((r[k] - o[k]) ** 2 for k in ("vx", "vy", "vz"))))
        compared += 1
    kept = []
    first = {}
    for r in sorted(rows, key=lambda r: r["frame"]):
        if r["vy"] > 0 and r["id"] not in first and r["frame"] > 0:
            first[r["id"]] = r  # the first frame after its first bounce (launched downwards)
    for i, r in first.items():
        h0 = [q for q in rows if q["id"] == i and q["frame"] == 0][0]
        s0 = math.hypot(h0["vx"], h0["vz"])
        if s0 > 0.1:
            kept.append(math.hypot(r["vx"], r["vz"]) / s0)
    spread = (max(kept) - min(kept)) if kept else 0
    ok = compared > 0 and worst <= p["tol"] and spread >= 0.8 * p["mu_hi"]
    return report(ok, "same response: %d rows compared, largest velocity difference %.3g m/s "
                  "(tolerance %g); the first bounce keeps %.3f to %.3f of the horizontal speed "
                  "over %d particles" % (compared, worst, p["tol"], min(kept or [0]),
                                         max(kept or [0]), len(kept)))


def check_bounce(rows, p):
    """A drop from h0 (above the plane y = 0) with resilience eps: the
    analytic apex y + vy^2/(2g) of every row after the n-th bounce equals
    eps^(2n) h0."""
    h0, eps, g = p["h0"], p["eps"], p["g"]
    nmax = int(p["n"])
    groups = []  # (apex values) per flight
    last = None
    for r_ in rows:
        E = r_["y"] + r_["vy"] ** 2 / (2 * g)
        if last is None or E < last * (1 - 0.25 * (1 - eps * eps)):
            groups.append([])
            last = E
        groups[-1].append(E)
    bad, worst, figs = [], 0.0, []
    if len(groups) < nmax + 1:
        bad.append("only %d flights seen" % len(groups))
    for n, gr in enumerate(groups[: nmax + 1]):
        want = eps ** (2 * n) * h0
        e = max(abs(E / want - 1) for E in gr)
        if n:
            worst = max(worst, e)
            figs.append("%d: %.7g (want %.7g)" % (n, sum(gr) / len(gr), want))
        if e > 1e-3:
            bad.append("apex %d: %.7g vs %.7g (rel %.3g)" % (n, max(gr, key=lambda E: abs(E - want)), want, e))
    return report(not bad, "bounce: apex heights %s; max relative error %.3g%s"
                  % (", ".join(figs), worst, "; BAD: " + "; ".join(bad) if bad else ""))


def check_chance(rows, p):
    """N particles fly down through a kill plane at y = 0 that affects a
    fraction `chance`: the survivors (all below it) are (1 - chance) N
    within 4 sigma."""
    N, ch, frame = int(p["N"]), p["chance"], int(p["frame"])
    last = [r_ for r_ in rows if int(r_["frame"]) == frame]
    above = sum(1 for r_ in last if r_["y"] >= 0)
    frac = len(last) / N
    want = 1 - ch
    sigma = math.sqrt(ch * (1 - ch) / N)
    ok = abs(frac - want) <= 4 * sigma and above == 0
    return report(ok, "chance: %d of %d passed (%.5f, expected %.2f +- %.5f = 4 sigma, %.2f sigma off), %d above the plane"
                  % (len(last), N, frac, want, 4 * sigma, (frac - want) / sigma, above))


def check_rest(rows, p):
    """A bouncing particle on the plane y = plane comes to rest: from the
    first row on it with vy = 0, every later row has y == plane and vy == 0
    exactly (and the rest is reached before `by` seconds)."""
    y0, by = p["plane"], p["by"]
    first = None
    for i, r_ in enumerate(rows):
        if r_["y"] == y0 and r_["vy"] == 0:
            first = i
            break
    if first is None:
        miny = min(r_["y"] for r_ in rows)
        return report(False, "rest: never at rest on the plane (min y %.9g vs plane %.9g, last vy %.3g)"
                      % (miny, y0, rows[-1]["vy"]))
    later = rows[first:]
    bad = [r_ for r_ in later if r_["y"] != y0 or r_["vy"] != 0]
    below = [r_ for r_ in rows if r_["y"] < y0]
    t_rest = rows[first]["time"]
    ok = not bad and not below and t_rest <= by and len(later) >= 10
    txt = "rest: at rest from t = %.4g s; %d later rows, %d off the plane or moving, %d rows below it" % (
        t_rest, len(later) - 1, len(bad), len(below))
    if bad:
        txt += "; first bad: t=%.4g y=%.9g vy=%.9g" % (bad[0]["time"], bad[0]["y"], bad[0]["vy"])
    return report(ok, txt)


def check_wake(rows, p):
    """A particle born at rest at x = x0 on the frictionless plane y = 0,
    pressed on it by gravity, with a push of `a` m/s^2 along +x from age
    `at`: before it, every row is exactly where it was born and still (the
    resting state changes no bit); after it, it slides exactly on the plane
    (y = 0, vy = 0) with x - x0 = a (t - at)^2 / 2 and vx = a (t - at).
    The push switches on at a step boundary, whose kick may take it or not:
    at most one step's impulse a dt in vx, a dt (t - at) in x."""
    x0, a, at, dt = p["x0"], p["a"], p["at"], p["dt"]
    before = [r for r in rows if r["time"] < at]
    after = [r for r in rows if r["time"] > at + dt]
    moved = [r for r in before if (r["x"], r["y"], r["z"], r["vx"], r["vy"], r["vz"]) != (x0, 0, 0, 0, 0, 0)]
    off = [r for r in after if r["y"] != 0 or r["vy"] != 0]
    worst_x = worst_v = 0.0
    far = []
    for r in after:
        s = r["time"] - at
        ex, ev = abs(r["x"] - x0 - a * s * s / 2), abs(r["vx"] - a * s)
        worst_x, worst_v = max(worst_x, ex / (a * dt * s)), max(worst_v, ev / (a * dt))
        if ex > a * dt * s + 1e-5 or ev > a * dt + 1e-5:
            far.append(r)
    ok = len(before) >= 10 and len(after) >= 10 and not moved and not off and not far
    txt = ("wake: %d rows at rest before t = %g (%d moved), %d after (%d off the plane, %d beyond "
           "the bound; worst x error %.2f, vx %.2f of one step's)" % (
               len(before), at, len(moved), len(after), len(off), len(far), worst_x, worst_v))
    return report(ok, txt)


CHECKS = {
    "vortex": check_vortex,
    "lorentz": check_lorentz,
    "orbit": check_orbit,
    "bounce": check_bounce,
    "kepler": check_kepler,
    "quadfall": check_quadfall,
    "magdrag": check_magdrag,
    "same_response": check_same_response,
    "chance": check_chance,
    "rest": check_rest,
    "wake": check_wake,
}


def main():
    if len(sys.argv) < 3 or sys.argv[1] not in CHECKS:
        sys.stderr.write("usage: check_bake.py {%s} CSV [key=value ...]\n" % "|".join(CHECKS))
        return 2
    p = {}
    for kv in sys.argv[3:]:
        k, v = kv.split("=", 1)
        try:
            p[k] = float(v)
        except ValueError:
            p[k] = v  # a path
    try:
        rows = load(sys.argv[2])
    except (OSError, ValueError, KeyError) as e:
        return report(False, "%s: cannot read %s: %s" % (sys.argv[1], sys.argv[2], e))
    return CHECKS[sys.argv[1]](rows, p)


if __name__ == "__main__":
    sys.exit(main())
