#!/usr/bin/env bash
# Births are uniform where the man page says, through the CLI: a burst of
# 40000 at time 0 (frame 0, age 0, speed 0 or 1: the baked position is
# the shape's sample and the velocity the spread's), chi-square over 20
# equal-probability bins of each coordinate the sampler inverts, at p =
# 0.001 (critical value 43.82 for 19 degrees of freedom):
#   sphere volume: (r / R)^3, z / r (Archimedes), the azimuth;
#   cone volume: q^3 with q = 1 - y / h (the section at q is a disc of
#   radius R q, so the volume below the apex grows as q^3), (rho / R q)^2
#   and the azimuth;
#   a 30-degree spread about +Y: cos(theta) uniform on [cos 30, 1] and the
#   azimuth.
# These are the births' own samplers run in blocks (sim/birth.c); the
# seed is fixed, so the statistics are the same every run. Each check also
# bins a biased reading of the same samples (r instead of r^3, q instead
# of q^3, theta instead of cos theta), which must fail: a test that
# cannot fail proves nothing.
#
#   bash run_birth_uniform.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" birth_uniform "$@"
cd "$work" || exit 2

cat >uniform.yaml <<'EOF'
pfx: 1
duration: 0.1
seed: 4
emitters:
  ball:
    shape: { type: sphere, radius: 2 }
    speed: 0
    lifetime: 10
    rate: 0
    bursts: [{ time: 0, count: 40000 }]
  cone:
    shape: { type: cone, radius: 0.5, height: 1.5 }
    speed: 0
    lifetime: 10
    rate: 0
    bursts: [{ time: 0, count: 40000 }]
  cap:
    shape: { type: point }
    spread: 30
    speed: 1
    lifetime: 10
    rate: 0
    bursts: [{ time: 0, count: 40000 }]
EOF

pfx_run bake uniform.yaml -o uniform.csv --frames 0:0 -q
if finished && want_status 0; then
    "$py" - uniform.csv >check.out 2>&1 <<'EOF'
import csv, math, sys

rows = {}
with open(sys.argv[1], newline="") as f:
    for r in csv.DictReader(f):
        rows.setdefault(r["emitter"], []).append([float(r[k]) for k in ("x", "y", "z", "vx", "vy", "vz")])

BINS, CRITICAL = 20, 43.82  # chi-square, 19 degrees of freedom, p = 0.001

def chi2(values):
    """Chi-square of values in [0, 1] over BINS equal bins."""
    counts = [0] * BINS
    for v in values:
        counts[min(BINS - 1, max(0, int(v * BINS)))] += 1
    e = len(values) / BINS
    return sum((c - e) ** 2 / e for c in counts)

def azimuth(a, b):
    return (math.atan2(b, a) / (2 * math.pi)) % 1.0

checks = []  # (name, statistic, must pass)
ball = rows["ball"]
R = 2.0
r = [math.sqrt(x * x + y * y + z * z) for x, y, z, *_ in ball]
checks.append(("sphere (r/R)^3", chi2([(v / R) ** 3 for v in r]), True))
checks.append(("sphere z/r", chi2([(p[2] / v + 1) / 2 for p, v in zip(ball, r)]), True))
checks.append(("sphere azimuth", chi2([azimuth(p[0], p[1]) for p in ball]), True))
checks.append(("sphere, biased r/R", chi2([v / R for v in r]), False))

cone = rows["cone"]
Rc, h = 0.5, 1.5
q = [1 - p[1] / h for p in cone]
checks.append(("cone q^3", chi2([v ** 3 for v in q]), True))
checks.append(("cone (rho/Rq)^2", chi2([(p[0] ** 2 + p[2] ** 2) / (Rc * v) ** 2 for p, v in zip(cone, q)]), True))
checks.append(("cone azimuth", chi2([azimuth(p[0], p[2]) for p in cone]), True))
checks.append(("cone, biased q", chi2(q), False))

cap = rows["cap"]
c30 = math.cos(math.radians(30))
checks.append(("spread cos(theta)", chi2([(p[4] - c30) / (1 - c30) for p in cap]), True))
checks.append(("spread azimuth", chi2([azimuth(p[3], p[5]) for p in cap]), True))
checks.append(("spread, biased theta", chi2([(1 - math.acos(min(1.0, p[4])) / math.radians(30)) for p in cap]), False))

bad = 0
for name, x, want in checks:
    ok = (x < CRITICAL) == want
    bad += not ok
    print("%s %s: chi2 %.1f (%s %.2f)" % ("ok  " if ok else "FAIL", name, x,
                                         "below" if want else "above", CRITICAL))
print("%d of %d rows: 40000 each" % (sum(len(v) for v in rows.values()), 120000))
sys.exit(1 if bad or any(len(v) != 40000 for v in rows.values()) else 0)
EOF
    status=$?
    begin "births uniform through pfx bake (chi-square, 20 bins, p = 0.001)"
    [ "$status" -eq 0 ] || flunk "$(cat check.out)"
    end
    sed 's/^/    /' check.out
fi

summary
