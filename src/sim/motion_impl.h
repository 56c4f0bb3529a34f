/* The integrators and force loops, written once over a real type. Not a
 * public header: integrators.c includes it twice, with PFX_REAL = float,
 * PFX_SUFFIX = _f, PFX_POOL = pfx_motion_pool_f, and again for double, so
 * the float pool and the double accuracy harness run the same arithmetic.
 * <tgmath.h> picks sqrtf/sqrt etc. by argument type. */

#define R PFX_REAL
#define FN(name) PFX_CAT(name, PFX_SUFFIX)
#define BLK PFX_MOTION_BLOCK
/* The float kernels' hot loops get an AVX2 copy (same bits: fast_f.h) */
#ifdef PFX_REAL_IS_FLOAT
#define CLONES PFX_CLONES
#else
#define CLONES
#endif

/* Region weight per particle: 1 inside, 1 - d/falloff at distance d
 * outside, 0 beyond. */
CLONES static void FN(region_weight)(const pfx_motion_region *g, size_t n, const R *x, const R *y,
                                     const R *z, R *w) {
    if (g->kind == PFX_REGION_NONE) {
        for (size_t j = 0; j < n; j++)
            w[j] = 1;
        return;
    }
    const R cx = (R)g->center[0], cy = (R)g->center[1], cz = (R)g->center[2];
    const R rad = (R)g->radius, fall = (R)g->falloff;
    const R hx = (R)g->half[0], hy = (R)g->half[1], hz = (R)g->half[2];
    const int sphere = g->kind == PFX_REGION_SPHERE;
    for (size_t j = 0; j < n; j++) {
        R dx = x[j] - cx, dy = y[j] - cy, dz = z[j] - cz, out;
        if (sphere) {
            out = sqrt(dx * dx + dy * dy + dz * dz) - rad;
        } else {
            R qx = fabs(dx) - hx, qy = fabs(dy) - hy, qz = fabs(dz) - hz;
            qx = qx > 0 ? qx : 0;
            qy = qy > 0 ? qy : 0;
            qz = qz > 0 ? qz : 0;
            out = sqrt(qx * qx + qy * qy + qz * qz);
        }
        R wj = out <= 0 ? (R)1 : (fall > 0 ? (R)1 - out / fall : (R)0);
        w[j] = wj > 0 ? wj : 0;
    }
}

/* Rodrigues' rotation of (u, v, w) about the unit axis (ux, uy, uz) by the
 * angle whose cosine and sine are c and s (the spiral's turn). */
static inline void FN(turn_about)(R ux, R uy, R uz, R c, R s, R *u, R *v, R *w) {
    R dot = ux * *u + uy * *v + uz * *w;
    R cx = uy * *w - uz * *v, cy = uz * *u - ux * *w, cz = ux * *v - uy * *u;
    R oc = dot * (1 - c);
    R nu = *u * c + cx * s + ux * oc, nv = *v * c + cy * s + uy * oc;
    *w = *w * c + cz * s + uz * oc;
    *u = nu;
    *v = nv;
}

/* force_over_life: a = curve(u), u = (t - birth) / lifetime, each
 * particle's normalised age at the stage time t (so every scheme sees the
 * force change within its step). In an animated emitter's space the curve's
 * vector turns with the emitter's rotation at t. */
static void FN(life_force)(const pfx_motion_force *F, const PFX_POOL *p, size_t i0, size_t n,
                           const R *x, const R *y, const R *z, double t, R *w, R *ax, R *ay,
                           R *az) {
    FN(region_weight)(&F->region, n, x, y, z, w);
    const double *tb = p->birth_time + i0;
    const R *life = p->lifetime + i0;
    double turn[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (F->frame) {
        emitter_pose pose;
        pfx_emitter_pose_at(F->frame, t, &pose);
        memcpy(turn, pose.rotation, sizeof turn);
    }
    for (size_t j = 0; j < n; j++) {
        double a[3];
        pfx_life_curve_at(F->life, (t - tb[j]) / (double)life[j], a);
        ax[j] += w[j] * (R)(turn[0] * a[0] + turn[1] * a[1] + turn[2] * a[2]);
        ay[j] += w[j] * (R)(turn[3] * a[0] + turn[4] * a[1] + turn[5] * a[2]);
        az[j] += w[j] * (R)(turn[6] * a[0] + turn[7] * a[1] + turn[8] * a[2]);
    }
}

/* a = sum of the ODE forces at (x, v, t) for pool particles i0 .. i0+n-1
 * (n <= BLK). split: leave out what the split step handles itself (the
 * folded linear parts, which its drift integrates exactly, and q v x B,
 * which its rotation does). */
CLONES static void FN(accel)(const pfx_motion_plan *m, const PFX_POOL *p, size_t i0, size_t n,
                             const R *restrict x, const R *restrict y, const R *restrict z,
                             const R *restrict vx, const R *restrict vy, const R *restrict vz,
                             double t, int split, R *restrict ax, R *restrict ay, R *restrict az) {
    R w[BLK];
    /* The columns are zeroed before the first force adds to them, unless
     * that is a float attractor, which starts the sum itself. */
    bool fresh = true;
    for (size_t f = 0; f < m->force_count; f++) {
        const pfx_motion_force *F = &m->forces[f];
        const int folded = split && m->folded[f];
        const pfx_motion_kind k = F->kind;
        const bool adds = !(k == PFX_MOTION_GRAVITY && folded) && k != PFX_MOTION_VORTEX &&
                          k != PFX_MOTION_SPIRAL && k != PFX_MOTION_SPEED_LIMIT;
#ifdef PFX_REAL_IS_FLOAT
        if (k == PFX_MOTION_ATTRACTOR) {
            const bool whole = F->region.kind == PFX_REGION_NONE;
            if (!whole)
                FN(region_weight)(&F->region, n, x, y, z, w);
            pfx_attractor_f(F, n, whole ? NULL : w, x, y, z, fresh, ax, ay, az);
            fresh = false;
            continue;
        }
#endif
        /* Without a region the weight is 1 and w[j] * a is a itself, bit
         * for bit: gravity and drag then skip the weight column (a store
         * and a load per particle and force), and a first unscaled gravity
         * writes 0 + g where the sum would start from zeros. */
        const bool whole = F->region.kind == PFX_REGION_NONE;
        if (fresh && adds && k == PFX_MOTION_GRAVITY && !folded && whole && !p->gravity_scale) {
            const R gx = (R)0 + (R)F->accel[0], gy = (R)0 + (R)F->accel[1],
                    gz = (R)0 + (R)F->accel[2];
            for (size_t j = 0; j < n; j++) {
                ax[j] = gx;
                ay[j] = gy;
                az[j] = gz;
            }
            fresh = false;
            continue;
        }
        if (fresh && adds) {
            for (size_t j = 0; j < n; j++)
                ax[j] = ay[j] = az[j] = 0;
            fresh = false;
        }
        switch (F->kind) {
        case PFX_MOTION_GRAVITY: {
            if (folded)
                break;
            if (whole && !p->gravity_scale) {
                const R gx = (R)F->accel[0], gy = (R)F->accel[1], gz = (R)F->accel[2];
                for (size_t j = 0; j < n; j++) {
                    ax[j] += gx;
                    ay[j] += gy;
                    az[j] += gz;
                }
                break;
            }
            FN(region_weight)(&F->region, n, x, y, z, w);
            const R gx = (R)F->accel[0], gy = (R)F->accel[1], gz = (R)F->accel[2];
            /* The scale folded into the weight first: a load under a
             * condition inside the loop below kept it from vectorising
             * (likewise the magnetic q/m, and the spring's anchors). */
            if (p->gravity_scale) {
                const R *gs = p->gravity_scale + i0;
                for (size_t j = 0; j < n; j++)
                    w[j] = gs[j] * w[j];
            }
            for (size_t j = 0; j < n; j++) {
                ax[j] += gx * w[j];
                ay[j] += gy * w[j];
                az[j] += gz * w[j];
            }
            break;
        }
        case PFX_MOTION_ATTRACTOR: {
            /* Plummer softening e: a = s d / (r^2 + e^2)^(3/2) (inverse
             * square); s d / (L (r^2 + e^2)) (linear); s d / (L^2 sqrt(r^2 +
             * e^2)) (constant); d = centre - x, so s > 0 attracts. All three
             * agree at r = L when e = 0. */
            /* (float: pfx_attractor_f above, the same loop vectorised) */
            FN(region_weight)(&F->region, n, x, y, z, w);
            const R cx = (R)F->center[0], cy = (R)F->center[1], cz = (R)F->center[2];
            const R s = (R)F->strength, e2 = (R)(F->softening * F->softening);
            const double Ld = F->ref_radius > 0 ? F->ref_radius : 1.0;
            const R L = (R)Ld, L2 = (R)(Ld * Ld);
            const R cut2 = F->radius > 0 ? (R)(F->radius * F->radius) : (R)INFINITY;
            const pfx_falloff fo = F->falloff;
            const int cube = fo == PFX_FALLOFF_INVERSE_SQUARE, lin = fo == PFX_FALLOFF_LINEAR;
            for (size_t j = 0; j < n; j++) {
                R dx = cx - x[j], dy = cy - y[j], dz = cz - z[j];
                R r2 = dx * dx + dy * dy + dz * dz, q = r2 + e2, sq = sqrt(q);
                R g = s / (cube ? q * sq : lin ? L * q : L2 * sq);
                /* at the unsoftened centre the direction is undefined; no
                 * branch, so the loop vectorises */
                g = ((q > 0) & (r2 <= cut2)) ? g : 0;
                g *= w[j];
                ax[j] += g * dx;
                ay[j] += g * dy;
                az[j] += g * dz;
            }
            break;
        }
        case PFX_MOTION_DRAG: {
            /* a = -(k + c |u|) u, u = v - wind. */
            const R k = folded ? (R)0 : (R)F->k, c = (R)F->c;
            const R wx = (R)F->wind[0], wy = (R)F->wind[1], wz = (R)F->wind[2];
            if (whole) {
                for (size_t j = 0; j < n; j++) {
                    R ux = vx[j] - wx, uy = vy[j] - wy, uz = vz[j] - wz;
                    R g = k + c * sqrt(ux * ux + uy * uy + uz * uz);
                    ax[j] -= g * ux;
                    ay[j] -= g * uy;
                    az[j] -= g * uz;
                }
                break;
            }
            FN(region_weight)(&F->region, n, x, y, z, w);
            for (size_t j = 0; j < n; j++) {
                R ux = vx[j] - wx, uy = vy[j] - wy, uz = vz[j] - wz;
                R g = (k + c * sqrt(ux * ux + uy * uy + uz * uz)) * w[j];
                ax[j] -= g * ux;
                ay[j] -= g * uy;
                az[j] -= g * uz;
            }
            break;
        }
        case PFX_MOTION_MAGNETIC: {
            /* a = (q/m)(E + v x B); the split step rotates by B itself. */
            FN(region_weight)(&F->region, n, x, y, z, w);
            const R Ex = (R)F->electric[0], Ey = (R)F->electric[1], Ez = (R)F->electric[2];
            const R Bx = split ? (R)0 : (R)F->field[0], By = split ? (R)0 : (R)F->field[1],
                    Bz = split ? (R)0 : (R)F->field[2];
            const R q0 = (R)F->charge, m0 = (R)(F->mass > 0 ? F->mass : 1.0);
            const R *qc = p->charge ? p->charge + i0 : NULL;
            const R *mc = p->mass ? p->mass + i0 : NULL;
            /* w becomes q/m times the weight, each particle's own where
             * the emitter draws charge or mass */
            if (qc || mc) {
                for (size_t j = 0; j < n; j++)
                    w[j] = (qc ? qc[j] : q0) / (mc ? mc[j] : m0) * w[j];
            } else {
                for (size_t j = 0; j < n; j++)
                    w[j] = q0 / m0 * w[j];
            }
            for (size_t j = 0; j < n; j++) {
                ax[j] += w[j] * (Ex + vy[j] * Bz - vz[j] * By);
                ay[j] += w[j] * (Ey + vz[j] * Bx - vx[j] * Bz);
                az[j] += w[j] * (Ez + vx[j] * By - vy[j] * Bx);
            }
            break;
        }
        case PFX_MOTION_SPRING: {
            /* a = -k (x - anchor) - 2 zeta sqrt(k) v: zeta = 1 is critical. */
            FN(region_weight)(&F->region, n, x, y, z, w);
            const R k = (R)F->k, cd = folded ? (R)0 : (R)(2.0 * F->zeta * sqrt(F->k));
            const R cx = (R)F->center[0], cy = (R)F->center[1], cz = (R)F->center[2];
            /* The anchors as columns, the birth places or the point
             * repeated: choosing one per particle inside the loop (a load
             * under a condition) kept it from vectorising. */
            R px[BLK], py[BLK], pz[BLK];
            const R *qx = px, *qy = py, *qz = pz;
            if (F->use_birth) {
                qx = p->bx + i0, qy = p->by + i0, qz = p->bz + i0;
            } else {
                for (size_t j = 0; j < n; j++)
                    px[j] = cx, py[j] = cy, pz[j] = cz;
            }
            for (size_t j = 0; j < n; j++) {
                ax[j] -= (k * (x[j] - qx[j]) + cd * vx[j]) * w[j];
                ay[j] -= (k * (y[j] - qy[j]) + cd * vy[j]) * w[j];
                az[j] -= (k * (z[j] - qz[j]) + cd * vz[j]) * w[j];
            }
            break;
        }
        case PFX_MOTION_TURBULENCE: {
            FN(region_weight)(&F->region, n, x, y, z, w);
            const double inv = 1.0 / F->scale, shift = F->speed * t * inv;
            const R s = (R)F->strength;
            float cx[BLK], cy[BLK], cz[BLK];
#ifdef PFX_REAL_IS_FLOAT
            pfx_curl_noise_f(n, x, y, z, (float)inv, shift, F->octaves, F->seed, cx, cy, cz);
#else
            float fx[BLK], fy[BLK], fz[BLK];
            for (size_t j = 0; j < n; j++)
                fx[j] = (float)x[j], fy[j] = (float)y[j], fz[j] = (float)z[j];
            pfx_curl_noise_f(n, fx, fy, fz, (float)inv, shift, F->octaves, F->seed, cx, cy, cz);
#endif
            for (size_t j = 0; j < n; j++) {
                ax[j] += s * w[j] * (R)cx[j];
                ay[j] += s * w[j] * (R)cy[j];
                az[j] += s * w[j] * (R)cz[j];
            }
            break;
        }
        case PFX_MOTION_FORCE_OVER_LIFE:
            FN(life_force)(F, p, i0, n, x, y, z, t, w, ax, ay, az);
            break;
        default: /* vortex, spiral, speed_limit: operators, not forces */
            break;
        }
    }
    for (size_t j = 0; j < n && fresh; j++)
        ax[j] = ay[j] = az[j] = 0;
}

/* ---- The schemes, each on one block of n particles in place ---- */

#define BLOCK_ARGS                                                                                 \
    const pfx_motion_plan *m, const PFX_POOL *p, size_t i0, size_t n, R *restrict X,               \
        R *restrict Y, R *restrict Z, R *restrict U, R *restrict V, R *restrict W, double t,       \
        double h

/* ---- Gravity and drag (plan gravity_drag), fused ----
 * Where the forces are unregioned gravities and one unregioned drag, the
 * acceleration reads v alone and costs a square root: the midpoint,
 * Verlet and RK4 steps below keep each particle's stages in registers
 * instead of passing 6 to 18 stage columns through accel and back. Each
 * is its scheme's loop above with accel inlined, every operation in the
 * same order on the same operands, so the bits are the same; the stage
 * positions, which only accel would read, are not formed. The drag scene
 * of tools/blender_compare.py (1e5 particles, one thread, births
 * included, best of 15 runs in turns): rk4 9.4 -> 4.6 ns a particle step,
 * verlet with 3 substeps 2.3 -> 2.1 ns a substep. */
typedef struct {
    R gx, gy, gz, k, c, wx, wy, wz;
} FN(gd_force);

/* The gravities' sum as accel forms it (0 + g1 + g2 ...), the drag's
 * constants; false where a gravity_scale column makes gravity per
 * particle (the general path then). */
static bool FN(gd_setup)(const pfx_motion_plan *m, const PFX_POOL *p, FN(gd_force) * f) {
    if (!m->gravity_drag || p->gravity_scale)
        return false;
    f->gx = f->gy = f->gz = 0;
    for (size_t i = 0; i < m->gd_drag; i++)
        if (m->forces[i].kind == PFX_MOTION_GRAVITY) {
            f->gx += (R)m->forces[i].accel[0];
            f->gy += (R)m->forces[i].accel[1];
            f->gz += (R)m->forces[i].accel[2];
        }
    const pfx_motion_force *D = &m->forces[m->gd_drag];
    f->k = (R)D->k, f->c = (R)D->c;
    f->wx = (R)D->wind[0], f->wy = (R)D->wind[1], f->wz = (R)D->wind[2];
    return true;
}

/* a = G - (k + c |u|) u, u = v - wind: accel's gravity sum, then its drag. */
#define GD_ACCEL(u, v, w, ax, ay, az)                                                              \
    do {                                                                                           \
        R ux_ = (u)-f.wx, uy_ = (v)-f.wy, uz_ = (w)-f.wz;                                          \
        R g_ = f.k + f.c * sqrt(ux_ * ux_ + uy_ * uy_ + uz_ * uz_);                                \
        ax = f.gx - g_ * ux_;                                                                      \
        ay = f.gy - g_ * uy_;                                                                      \
        az = f.gz - g_ * uz_;                                                                      \
    } while (0)

CLONES static void FN(gd_midpoint)(FN(gd_force) f, size_t n, R *restrict X, R *restrict Y,
                                   R *restrict Z, R *restrict U, R *restrict V, R *restrict W,
                                   double h) {
    const R hr = (R)h, h2 = (R)(0.5 * h);
    for (size_t j = 0; j < n; j++) {
        R ax, ay, az;
        GD_ACCEL(U[j], V[j], W[j], ax, ay, az);
        const R mu = U[j] + h2 * ax, mv = V[j] + h2 * ay, mw = W[j] + h2 * az;
        GD_ACCEL(mu, mv, mw, ax, ay, az);
        X[j] += hr * mu;
        Y[j] += hr * mv;
        Z[j] += hr * mw;
        U[j] += hr * ax;
        V[j] += hr * ay;
        W[j] += hr * az;
    }
}

CLONES static void FN(gd_verlet)(FN(gd_force) f, size_t n, R *restrict X, R *restrict Y,
                                 R *restrict Z, R *restrict U, R *restrict V, R *restrict W,
                                 double h) {
    const R hr = (R)h, h2 = (R)(0.5 * h);
    for (size_t j = 0; j < n; j++) {
        R ax, ay, az;
        GD_ACCEL(U[j], V[j], W[j], ax, ay, az);
        const R u = U[j] + h2 * ax, v = V[j] + h2 * ay, w = W[j] + h2 * az;
        X[j] += hr * u;
        Y[j] += hr * v;
        Z[j] += hr * w;
        const R pu = u + h2 * ax, pv = v + h2 * ay, pw = w + h2 * az;
        GD_ACCEL(pu, pv, pw, ax, ay, az);
        U[j] = u + h2 * ax;
        V[j] = v + h2 * ay;
        W[j] = w + h2 * az;
    }
}

CLONES static void FN(gd_rk4)(FN(gd_force) f, size_t n, R *restrict X, R *restrict Y, R *restrict Z,
                              R *restrict U, R *restrict V, R *restrict W, double h) {
    const R hr = (R)h, h2 = (R)(0.5 * h), h6 = (R)(h / 6.0);
    for (size_t j = 0; j < n; j++) {
        const R u0 = U[j], v0 = V[j], w0 = W[j];
        R ax, ay, az;
        GD_ACCEL(u0, v0, w0, ax, ay, az);
        R sx = u0, sy = v0, sz = w0, su = ax, sv = ay, sw = az;
        R tu = u0 + h2 * ax, tv = v0 + h2 * ay, tw = w0 + h2 * az;
        for (int stage = 2; stage <= 3; stage++) {
            GD_ACCEL(tu, tv, tw, ax, ay, az);
            const R c = stage == 2 ? h2 : hr;
            sx += 2 * tu, sy += 2 * tv, sz += 2 * tw;
            su += 2 * ax, sv += 2 * ay, sw += 2 * az;
            tu = u0 + c * ax, tv = v0 + c * ay, tw = w0 + c * az;
        }
        GD_ACCEL(tu, tv, tw, ax, ay, az);
        X[j] += h6 * (sx + tu);
        Y[j] += h6 * (sy + tv);
        Z[j] += h6 * (sz + tw);
        U[j] += h6 * (su + ax);
        V[j] += h6 * (sv + ay);
        W[j] += h6 * (sw + az);
    }
}
#undef GD_ACCEL

/* Explicit Euler: x1 = x0 + h v0, v1 = v0 + h a(x0, v0). Order 1; energy
 * grows every step on any oscillator. */
CLONES static void FN(step_euler)(BLOCK_ARGS) {
    R ax[BLK], ay[BLK], az[BLK];
    FN(accel)(m, p, i0, n, X, Y, Z, U, V, W, t, 0, ax, ay, az);
    const R hr = (R)h;
    for (size_t j = 0; j < n; j++) {
        X[j] += hr * U[j];
        Y[j] += hr * V[j];
        Z[j] += hr * W[j];
        U[j] += hr * ax[j];
        V[j] += hr * ay[j];
        W[j] += hr * az[j];
    }
}

/* Semi-implicit (symplectic) Euler: v1 = v0 + h a(x0, v0), x1 = x0 + h v1.
 * Order 1, but symplectic for position forces: orbits stay bounded. */
CLONES static void FN(step_symplectic)(BLOCK_ARGS) {
    R ax[BLK], ay[BLK], az[BLK];
    FN(accel)(m, p, i0, n, X, Y, Z, U, V, W, t, 0, ax, ay, az);
    const R hr = (R)h;
    for (size_t j = 0; j < n; j++) {
        U[j] += hr * ax[j];
        V[j] += hr * ay[j];
        W[j] += hr * az[j];
        X[j] += hr * U[j];
        Y[j] += hr * V[j];
        Z[j] += hr * W[j];
    }
}

/* Explicit midpoint (RK2): half an Euler step to the middle, then the full
 * step with the midpoint's slope. Order 2. */
CLONES static void FN(step_midpoint)(BLOCK_ARGS) {
    R ax[BLK], ay[BLK], az[BLK], mx[BLK], my[BLK], mz[BLK], mu[BLK], mv[BLK], mw[BLK];
    if (n == 0) /* (so that the stage columns below are never passed unwritten) */
        return;
    FN(accel)(m, p, i0, n, X, Y, Z, U, V, W, t, 0, ax, ay, az);
    const R hr = (R)h, h2 = (R)(0.5 * h);
    for (size_t j = 0; j < n; j++) {
        mx[j] = X[j] + h2 * U[j];
        my[j] = Y[j] + h2 * V[j];
        mz[j] = Z[j] + h2 * W[j];
        mu[j] = U[j] + h2 * ax[j];
        mv[j] = V[j] + h2 * ay[j];
        mw[j] = W[j] + h2 * az[j];
    }
    FN(accel)(m, p, i0, n, mx, my, mz, mu, mv, mw, t + 0.5 * h, 0, ax, ay, az);
    for (size_t j = 0; j < n; j++) {
        X[j] += hr * mu[j];
        Y[j] += hr * mv[j];
        Z[j] += hr * mw[j];
        U[j] += hr * ax[j];
        V[j] += hr * ay[j];
        W[j] += hr * az[j];
    }
}

/* Velocity Verlet (kick-drift-kick): v' = v0 + h/2 a0, x1 = x0 + h v',
 * v1 = v' + h/2 a(x1, vp). For position forces vp does not matter and this
 * is the textbook symplectic scheme; for velocity forces vp = v' + h/2 a0
 * predicts v1 to O(h^2), which keeps the method second order. 2 evaluations
 * (a cached a1 would make it 1, at 3 more columns per particle). */
CLONES static void FN(step_verlet)(BLOCK_ARGS) {
    R ax[BLK], ay[BLK], az[BLK], pu[BLK], pv[BLK], pw[BLK];
    if (n == 0) /* (so that the stage columns below are never passed unwritten) */
        return;
    FN(accel)(m, p, i0, n, X, Y, Z, U, V, W, t, 0, ax, ay, az);
    const R hr = (R)h, h2 = (R)(0.5 * h);
    for (size_t j = 0; j < n; j++) {
        U[j] += h2 * ax[j];
        V[j] += h2 * ay[j];
        W[j] += h2 * az[j];
        X[j] += hr * U[j];
        Y[j] += hr * V[j];
        Z[j] += hr * W[j];
        pu[j] = U[j] + h2 * ax[j];
        pv[j] = V[j] + h2 * ay[j];
        pw[j] = W[j] + h2 * az[j];
    }
    FN(accel)(m, p, i0, n, X, Y, Z, pu, pv, pw, t + h, 0, ax, ay, az);
    for (size_t j = 0; j < n; j++) {
        U[j] += h2 * ax[j];
        V[j] += h2 * ay[j];
        W[j] += h2 * az[j];
    }
}

/* Classical RK4 on q' = (v, a(x, v, t)). The pool holds the start state
 * until the end; t* is the stage state, s* the weighted slope sum
 * k1 + 2 k2 + 2 k3 + k4. Order 4. */
CLONES static void FN(step_rk4)(BLOCK_ARGS) {
    R ax[BLK], ay[BLK], az[BLK];
    R tx[BLK], ty[BLK], tz[BLK], tu[BLK], tv[BLK], tw[BLK];
    R sx[BLK], sy[BLK], sz[BLK], su[BLK], sv[BLK], sw[BLK];
    const R hr = (R)h, h2 = (R)(0.5 * h), h6 = (R)(h / 6.0);
    FN(accel)(m, p, i0, n, X, Y, Z, U, V, W, t, 0, ax, ay, az);
    for (size_t j = 0; j < n; j++) {
        sx[j] = U[j], sy[j] = V[j], sz[j] = W[j];
        su[j] = ax[j], sv[j] = ay[j], sw[j] = az[j];
        tx[j] = X[j] + h2 * U[j], ty[j] = Y[j] + h2 * V[j], tz[j] = Z[j] + h2 * W[j];
        tu[j] = U[j] + h2 * ax[j], tv[j] = V[j] + h2 * ay[j], tw[j] = W[j] + h2 * az[j];
    }
    for (int stage = 2; stage <= 3; stage++) {
        FN(accel)(m, p, i0, n, tx, ty, tz, tu, tv, tw, t + 0.5 * h, 0, ax, ay, az);
        const R c = stage == 2 ? h2 : hr; /* k3's state is a half step, k4's a full one */
        for (size_t j = 0; j < n; j++) {
            sx[j] += 2 * tu[j], sy[j] += 2 * tv[j], sz[j] += 2 * tw[j];
            su[j] += 2 * ax[j], sv[j] += 2 * ay[j], sw[j] += 2 * az[j];
            tx[j] = X[j] + c * tu[j], ty[j] = Y[j] + c * tv[j], tz[j] = Z[j] + c * tw[j];
            tu[j] = U[j] + c * ax[j], tv[j] = V[j] + c * ay[j], tw[j] = W[j] + c * az[j];
        }
    }
    FN(accel)(m, p, i0, n, tx, ty, tz, tu, tv, tw, t + h, 0, ax, ay, az);
    for (size_t j = 0; j < n; j++) {
        X[j] += h6 * (sx[j] + tu[j]);
        Y[j] += h6 * (sy[j] + tv[j]);
        Z[j] += h6 * (sz[j] + tw[j]);
        U[j] += h6 * (su[j] + ax[j]);
        V[j] += h6 * (sv[j] + ay[j]);
        W[j] += h6 * (sw[j] + az[j]);
    }
}

/* The exact flow of v' = s g - k (v - w) for time h (s = gravity_scale):
 *   u0 = v0 - w,  e = exp(-k h),  E1 = (1 - e)/k,  E2 = (h - E1)/k,
 *   v = w + u0 e + s g E1,  x = x0 + w h + u0 E1 + s g E2.
 * E1 = -expm1(-kh)/k and E2 by its series h^2 sum (-kh)^n/(n+2)! when kh <
 * 0.5, so k -> 0 gives E1 = h, E2 = h^2/2: the exact projectile, without
 * the cancellation of v_inf = w + g/k. Scalars in double, once per call. */
CLONES static void FN(drift)(const pfx_motion_plan *m, const PFX_POOL *p, size_t i0, size_t n,
                             R *restrict X, R *restrict Y, R *restrict Z, R *restrict U,
                             R *restrict V, R *restrict W, double h) {
    const double k = m->drift_k, zk = k * h;
    double e = 1, E1 = h, E2 = 0.5 * h * h;
    if (k > 0) {
        e = exp(-zk);
        E1 = -expm1(-zk) / k;
        if (zk < 0.5) {
            double term = 0.5, sum = 0; /* (-z)^n / (n+2)! */
            for (int i = 0; i < 16; i++) {
                sum += term;
                term *= -zk / (double)(i + 3);
            }
            E2 = h * h * sum;
        } else {
            E2 = (h - E1) / k;
        }
    }
    const R re = (R)e, r1 = (R)E1, r2 = (R)E2, hr = (R)h;
    const R wx = (R)m->drift_wind[0], wy = (R)m->drift_wind[1], wz = (R)m->drift_wind[2];
    const R gx = (R)m->drift_g[0], gy = (R)m->drift_g[1], gz = (R)m->drift_g[2];
    const R *gs = p->gravity_scale ? p->gravity_scale + i0 : NULL;
    /* Two copies of one loop, with and without the scale column: a select
     * per particle between them would keep the loop from vectorising. */
#define DRIFT_ONE(s)                                                                               \
    do {                                                                                           \
        R ux = U[j] - wx, uy = V[j] - wy, uz = W[j] - wz;                                          \
        X[j] += wx * hr + ux * r1 + (s)*gx * r2;                                                   \
        Y[j] += wy * hr + uy * r1 + (s)*gy * r2;                                                   \
        Z[j] += wz * hr + uz * r1 + (s)*gz * r2;                                                   \
        U[j] = wx + ux * re + (s)*gx * r1;                                                         \
        V[j] = wy + uy * re + (s)*gy * r1;                                                         \
        W[j] = wz + uz * re + (s)*gz * r1;                                                         \
    } while (0)
    if (gs)
        for (size_t j = 0; j < n; j++)
            DRIFT_ONE(gs[j]);
    else
        for (size_t j = 0; j < n; j++)
            DRIFT_ONE((R)1);
#undef DRIFT_ONE
}

/* Boris rotation of v by the magnetic forces for time h: v' = Omega x v with
 * Omega = -(q/m) B summed over the fields. With t = tan(theta/2) Omega_hat
 * and s = 2t/(1 + t^2): v- = v + v x t, v = v + v- x s, a rotation by
 * exactly theta = |Omega| h, so |v| is kept to round-off. (Boris's
 * t = qB h/(2m) rotates by 2 atan(theta/2), a phase error of theta^3/12 per
 * step; the tangent removes it at one tan per particle.) */
CLONES static void FN(rotate)(const pfx_motion_plan *m, const PFX_POOL *p, size_t i0, size_t n,
                              const R *X, const R *Y, const R *Z, R *U, R *V, R *W, double h) {
    R ox[BLK], oy[BLK], oz[BLK], w[BLK];
    if (m->uniform_rotation && !p->charge && !p->mass) {
        /* one Omega for every particle: the tangent once per block */
        double om =
            sqrt(m->omega[0] * m->omega[0] + m->omega[1] * m->omega[1] + m->omega[2] * m->omega[2]);
        double c = tan(0.5 * om * h) / om;
        const R tx = (R)(m->omega[0] * c), ty = (R)(m->omega[1] * c), tz = (R)(m->omega[2] * c);
        const R sc = (R)(2 / (1 + (double)tx * tx + (double)ty * ty + (double)tz * tz));
        const R sx = tx * sc, sy = ty * sc, sz = tz * sc;
        for (size_t j = 0; j < n; j++) {
            R au = U[j] + (ty * W[j] - tz * V[j]);
            R av = V[j] + (tz * U[j] - tx * W[j]);
            R aw = W[j] + (tx * V[j] - ty * U[j]);
            U[j] += sy * aw - sz * av;
            V[j] += sz * au - sx * aw;
            W[j] += sx * av - sy * au;
        }
        return;
    }
    for (size_t j = 0; j < n; j++)
        ox[j] = oy[j] = oz[j] = 0;
    for (size_t f = 0; f < m->force_count; f++) {
        const pfx_motion_force *F = &m->forces[f];
        if (F->kind != PFX_MOTION_MAGNETIC)
            continue;
        FN(region_weight)(&F->region, n, X, Y, Z, w);
        const R Bx = (R)F->field[0], By = (R)F->field[1], Bz = (R)F->field[2];
        const R q0 = (R)F->charge, m0 = (R)(F->mass > 0 ? F->mass : 1.0);
        const R *qc = p->charge ? p->charge + i0 : NULL;
        const R *mc = p->mass ? p->mass + i0 : NULL;
        for (size_t j = 0; j < n; j++) {
            R qm = (qc ? qc[j] : q0) / (mc ? mc[j] : m0) * w[j];
            ox[j] -= qm * Bx;
            oy[j] -= qm * By;
            oz[j] -= qm * Bz;
        }
    }
    for (size_t j = 0; j < n; j++) {
        double om = sqrt((double)ox[j] * ox[j] + (double)oy[j] * oy[j] + (double)oz[j] * oz[j]);
        if (!(om > 0))
            continue;
        double th = om * h;
        R c = (R)(tan(0.5 * th) / om);
        R tx = ox[j] * c, ty = oy[j] * c, tz = oz[j] * c;
        R sc = 2 / (1 + tx * tx + ty * ty + tz * tz);
        R sx = tx * sc, sy = ty * sc, sz = tz * sc;
        /* v x t for v' = Omega x v: the rotation sense is Omega's, so
         * use t x v (= -(v x t)). */
        R au = U[j] + (ty * W[j] - tz * V[j]);
        R av = V[j] + (tz * U[j] - tx * W[j]);
        R aw = W[j] + (tx * V[j] - ty * U[j]);
        U[j] += sy * aw - sz * av;
        V[j] += sz * au - sx * aw;
        W[j] += sx * av - sy * au;
    }
}

/* v += h2 a: half a kick of the split step. */
static inline void FN(half_kick)(size_t n, R *U, R *V, R *W, const R *ax, const R *ay, const R *az,
                                 R h2) {
    for (size_t j = 0; j < n; j++) {
        U[j] += h2 * ax[j];
        V[j] += h2 * ay[j];
        W[j] += h2 * az[j];
    }
}

/* Between the two half kicks: half the rotation, the exact drift over h,
 * the other half of the rotation. */
static inline void FN(between_kicks)(const pfx_motion_plan *m, const PFX_POOL *p, size_t i0,
                                     size_t n, R *X, R *Y, R *Z, R *U, R *V, R *W, double h) {
    if (m->has_rotation)
        FN(rotate)(m, p, i0, n, X, Y, Z, U, V, W, 0.5 * h);
    FN(drift)(m, p, i0, n, X, Y, Z, U, V, W, h);
    if (m->has_rotation)
        FN(rotate)(m, p, i0, n, X, Y, Z, U, V, W, 0.5 * h);
}

/* Half a kick by forces that read v (plan kick_reads_v: quadratic drag,
 * drag or damping in a region): the kick is then itself an ODE in v at
 * fixed x, and one Euler stage over h/2 (local error O(h^2)) would leave
 * the whole split step first order. The explicit midpoint rule over h/2,
 * v_m = v + h/4 a(x, v), v += h/2 a(x, v_m), has local error O(h^3), so
 * the symmetric composition K R D R K stays second order (Strang). Forces
 * of x alone give a(x, v_m) = a(x, v): the same kick, one evaluation more. */
static void FN(velocity_half_kick)(const pfx_motion_plan *m, const PFX_POOL *p, size_t i0, size_t n,
                                   R *X, R *Y, R *Z, R *U, R *V, R *W, double t, double h, R *ax,
                                   R *ay, R *az) {
    R mu[BLK], mv[BLK], mw[BLK];
    const R h4 = (R)(0.25 * h);
    if (n == 0) /* (so that the stage columns below are never passed unwritten) */
        return;
    FN(accel)(m, p, i0, n, X, Y, Z, U, V, W, t, 1, ax, ay, az);
    for (size_t j = 0; j < n; j++) {
        mu[j] = U[j] + h4 * ax[j];
        mv[j] = V[j] + h4 * ay[j];
        mw[j] = W[j] + h4 * az[j];
    }
    FN(accel)(m, p, i0, n, X, Y, Z, mu, mv, mw, t, 1, ax, ay, az);
    FN(half_kick)(n, U, V, W, ax, ay, az, (R)(0.5 * h));
}

/* The split step: K(h/2) R(h/2) D(h) R(h/2) K(h/2) - kicks by the forces
 * that are not folded, the Boris rotation, the exact drift of gravity and
 * linear drag. Symmetric, hence second order (each half kick by forces
 * that read v is a midpoint stage: velocity_half_kick); exact when only
 * gravity and linear drag act; symplectic (kick-drift-kick) for position
 * forces. The closing kick is evaluated at t_close, the next substep's
 * start (t + h, or the step's own end time: see run_split). */
CLONES static void FN(step_split)(BLOCK_ARGS, double t_close) {
    R ax[BLK], ay[BLK], az[BLK];
    const R h2 = (R)(0.5 * h);
    if (m->has_kick && m->kick_reads_v) {
        FN(velocity_half_kick)(m, p, i0, n, X, Y, Z, U, V, W, t, h, ax, ay, az);
        FN(between_kicks)(m, p, i0, n, X, Y, Z, U, V, W, h);
        FN(velocity_half_kick)(m, p, i0, n, X, Y, Z, U, V, W, t_close, h, ax, ay, az);
        return;
    }
    if (m->has_kick) {
        FN(accel)(m, p, i0, n, X, Y, Z, U, V, W, t, 1, ax, ay, az);
        FN(half_kick)(n, U, V, W, ax, ay, az, h2);
    }
    FN(between_kicks)(m, p, i0, n, X, Y, Z, U, V, W, h);
    if (m->has_kick) {
        FN(accel)(m, p, i0, n, X, Y, Z, U, V, W, t_close, 1, ax, ay, az);
        FN(half_kick)(n, U, V, W, ax, ay, az, h2);
    }
}

CLONES static void FN(operators)(const pfx_motion_plan *m, size_t n, R *X, R *Y, R *Z, R *U, R *V,
                                 R *W, double h, bool reverse);

/* The time substep s of `steps` starts at: t + s h, and the last one ends
 * at t_end exactly (the caller's end of the step, which is the next step's
 * start bit for bit), so a kick evaluated at a substep's end and one at the
 * next substep's start see the same time. */
static inline double FN(substep_time)(double t, double h, int s, int steps, double t_end) {
    return s < steps ? t + s * h : t_end;
}

/* The opening kick's acceleration from the pool's carried column (plan
 * carry_accel): when no particle of the block has NaN there, each holds
 * the acceleration at its position and this time, computed by the closing
 * kick of the step before (sim/step.c keeps it so: births, deflector hits
 * and wraps write NaN), and the forces read nothing else, so it is the
 * very value a new evaluation would give. Returns whether it took it. */
static bool FN(take_carried)(const PFX_POOL *p, size_t i0, size_t n, R *ax, R *ay, R *az) {
    const R *cx = p->ax + i0, *cy = p->ay + i0, *cz = p->az + i0;
    int unknown = 0;
    for (size_t j = 0; j < n; j++)
        unknown |= cx[j] != cx[j];
    if (unknown)
        return false;
    memcpy(ax, cx, n * sizeof *ax);
    memcpy(ay, cy, n * sizeof *ay);
    memcpy(az, cz, n * sizeof *az);
    return true;
}

/* Strang splitting of the operators about each substep of h: over h / 2
 * in the order of the forces before it (operate_first, and operate_after
 * for the next substep) and over h / 2 in the reverse order after it
 * (operate_after), a palindrome, so the whole is second order (with a
 * scheme of second order or more) where applying the operators whole
 * after each substep was first order: a spiral's turn of v came a step
 * late to x (sword_swipe: the error halved per doubling of the rate, for
 * rk4 as for auto). In one order both times, two operators that do not
 * commute (tornado's two vortices, the pull's inflow changing the twist's
 * rate) stayed first order. */
static inline void FN(operate_first)(const pfx_motion_plan *m, size_t n, R *X, R *Y, R *Z, R *U,
                                     R *V, R *W, double h) {
    if (m->has_operators)
        FN(operators)(m, n, X, Y, Z, U, V, W, 0.5 * h, false);
}

static inline void FN(operate_after)(const pfx_motion_plan *m, size_t n, R *X, R *Y, R *Z, R *U,
                                     R *V, R *W, double h, int s, int steps) {
    if (!m->has_operators)
        return;
    FN(operators)(m, n, X, Y, Z, U, V, W, 0.5 * h, true);
    if (s + 1 < steps)
        FN(operators)(m, n, X, Y, Z, U, V, W, 0.5 * h, false);
}

/* `steps` split steps of h from t (plan kick_carries): the closing kick of
 * a substep and the opening kick of the next evaluate the forces at the
 * same positions and time, and these forces read nothing else, so the one
 * evaluation serves both (first same as last): steps + 1 evaluations
 * instead of 2 steps, and the same bits as step_split run steps times.
 * With the plan's carry_accel and a pool that has the column, the first
 * evaluation comes from the step before and the last is kept for the step
 * after: one evaluation a step. */
CLONES static void FN(run_split_carried)(const pfx_motion_plan *m, const PFX_POOL *p, size_t i0,
                                         size_t n, R *X, R *Y, R *Z, R *U, R *V, R *W, double t,
                                         double h, int steps, double t_end) {
    R ax[BLK], ay[BLK], az[BLK];
    const R h2 = (R)(0.5 * h);
    const bool carry = m->carry_accel && p->ax;
    if (!carry || !FN(take_carried)(p, i0, n, ax, ay, az))
        FN(accel)(m, p, i0, n, X, Y, Z, U, V, W, t, 1, ax, ay, az);
    FN(operate_first)(m, n, X, Y, Z, U, V, W, h);
    for (int s = 0; s < steps; s++) {
        FN(half_kick)(n, U, V, W, ax, ay, az, h2);
        FN(between_kicks)(m, p, i0, n, X, Y, Z, U, V, W, h);
        const double t_close = FN(substep_time)(t, h, s + 1, steps, t_end);
        FN(accel)(m, p, i0, n, X, Y, Z, U, V, W, t_close, 1, ax, ay, az);
        FN(half_kick)(n, U, V, W, ax, ay, az, h2);
        FN(operate_after)(m, n, X, Y, Z, U, V, W, h, s, steps); /* on v alone (kick_carries) */
    }
    if (carry) {
        memcpy(p->ax + i0, ax, n * sizeof *ax);
        memcpy(p->ay + i0, ay, n * sizeof *ay);
        memcpy(p->az + i0, az, n * sizeof *az);
    }
}

/* The Sims vortex F's turn (strength f(r) w h about its axis) and pull
 * (inflow f(r) w h towards it) on n positions, f and the region weight w
 * read at (EX, EY, EZ), or at each position itself where EX is NULL. */
CLONES static void FN(vortex_turn)(const pfx_motion_force *F, size_t n, const R *EX, const R *EY,
                                   const R *EZ, R *X, R *Y, R *Z, double h) {
    R w[BLK];
    const bool whole = F->region.kind == PFX_REGION_NONE;
    if (!whole)
        FN(region_weight)(&F->region, n, EX ? EX : X, EX ? EY : Y, EX ? EZ : Z, w);
#ifdef PFX_REAL_IS_FLOAT
    /* the same operator in float, vectorised (no weights: 1) */
    pfx_vortex_f(F, n, whole ? NULL : w, EX, EY, EZ, X, Y, Z, h);
    return;
#endif
    const double ux = F->axis[0], uy = F->axis[1], uz = F->axis[2];
    const double inv_rad = 1.0 / F->radius, d = F->sims_d;
    for (size_t j = 0; j < n; j++) {
        const double wj = whole ? 1.0 : (double)w[j];
        double ex = (EX ? EX : X)[j] - F->center[0], ey = (EX ? EY : Y)[j] - F->center[1],
               ez = (EX ? EZ : Z)[j] - F->center[2];
        double ea = ex * ux + ey * uy + ez * uz;
        ex -= ea * ux, ey -= ea * uy, ez -= ea * uz;
        double rn = sqrt(ex * ex + ey * ey + ez * ez) * inv_rad;
        if (!(rn < 1))
            continue;
        double rx = X[j] - F->center[0], ry = Y[j] - F->center[1], rz = Z[j] - F->center[2];
        double al = rx * ux + ry * uy + rz * uz;
        double qx = rx - al * ux, qy = ry - al * uy, qz = rz - al * uz;
        double rp = sqrt(qx * qx + qy * qy + qz * qz);
        double fr = pfx_vortex_falloff(rn, d);
        double th = F->strength * fr * wj * h, c = cos(th), s = sin(th);
        double cx = uy * qz - uz * qy, cy = uz * qx - ux * qz, cz = ux * qy - uy * qx;
        double nx = qx * c + cx * s, ny = qy * c + cy * s, nz = qz * c + cz * s;
        if (F->inflow != 0 && rp > 0) {
            double g = 1 - F->inflow * fr * wj * h / rp;
            g = g > 0 ? g : 0;
            nx *= g, ny *= g, nz *= g;
        }
        X[j] = (R)(F->center[0] + al * ux + nx);
        Y[j] = (R)(F->center[1] + al * uy + ny);
        Z[j] = (R)(F->center[2] + al * uz + nz);
    }
}

/* The vortex over h, second order in h. Unregioned and without inflow a
 * particle keeps its distance r from the axis, so turning it by
 * strength f(r) h is the exact flow. Otherwise the rate changes along the
 * way (the region weight round the circle, f(r) as the inflow pulls it
 * in): the turn and pull are read at the midpoint of the step (the
 * position turned over h / 2), the explicit midpoint rule, not at its
 * start, which was first order (tornado's pull converged at 1/h). */
CLONES static void FN(vortex)(const pfx_motion_force *F, size_t n, R *X, R *Y, R *Z, double h) {
    if (F->region.kind == PFX_REGION_NONE && F->inflow == 0) {
        FN(vortex_turn)(F, n, NULL, NULL, NULL, X, Y, Z, h);
        return;
    }
    R mx[BLK], my[BLK], mz[BLK];
    memcpy(mx, X, n * sizeof *mx);
    memcpy(my, Y, n * sizeof *my);
    memcpy(mz, Z, n * sizeof *mz);
    FN(vortex_turn)(F, n, NULL, NULL, NULL, mx, my, mz, 0.5 * h);
    FN(vortex_turn)(F, n, mx, my, mz, X, Y, Z, h);
}

/* Operators that are rotations or clamps rather than forces, applied
 * about each (sub)step (Strang splitting, see operate_first), in the
 * order of the forces or its reverse: the Sims vortex
 * turns the position about its axis by strength f(r) h (and pulls it in
 * by inflow f(r) h); the spiral turns the velocity by rate h (Rodrigues);
 * speed_limit scales |v| down. */
CLONES static void FN(operators)(const pfx_motion_plan *m, size_t n, R *X, R *Y, R *Z, R *U, R *V,
                                 R *W, double h, bool reverse) {
    R w[BLK];
    for (size_t k = 0; k < m->force_count; k++) {
        const pfx_motion_force *F = &m->forces[reverse ? m->force_count - 1 - k : k];
        if (F->kind == PFX_MOTION_VORTEX) {
            FN(vortex)(F, n, X, Y, Z, h);
        } else if (F->kind == PFX_MOTION_SPIRAL) {
            const R ux = (R)F->axis[0], uy = (R)F->axis[1], uz = (R)F->axis[2];
            /* Unregioned, every particle turns by the same angle: its cosine
             * and sine once (the same numbers each particle would get). */
            const int uniform = F->region.kind == PFX_REGION_NONE;
            if (uniform) {
                const double th = F->rate * 1.0 * h;
                const R c = (R)cos(th), s = (R)sin(th);
                for (size_t j = 0; j < n; j++)
                    FN(turn_about)(ux, uy, uz, c, s, &U[j], &V[j], &W[j]);
                continue;
            }
            FN(region_weight)(&F->region, n, X, Y, Z, w);
            for (size_t j = 0; j < n; j++) {
                double th = F->rate * (double)w[j] * h;
                FN(turn_about)(ux, uy, uz, (R)cos(th), (R)sin(th), &U[j], &V[j], &W[j]);
            }
        } else if (F->kind == PFX_MOTION_SPEED_LIMIT) {
            FN(region_weight)(&F->region, n, X, Y, Z, w);
            const R vmax = (R)F->max_speed;
            for (size_t j = 0; j < n; j++) {
                R sp = sqrt(U[j] * U[j] + V[j] * V[j] + W[j] * W[j]);
                if (sp > vmax) {
                    R g = 1 - w[j] + w[j] * vmax / sp;
                    U[j] *= g, V[j] *= g, W[j] *= g;
                }
            }
        }
    }
}

/* `steps` split substeps of h from t on n particles in place, the last
 * ending at t_end. */
static void FN(run_split)(const pfx_motion_plan *m, const PFX_POOL *p, size_t i0, size_t n, R *X,
                          R *Y, R *Z, R *U, R *V, R *W, double t, double h, int steps,
                          double t_end) {
    if (m->kick_carries) {
        FN(run_split_carried)(m, p, i0, n, X, Y, Z, U, V, W, t, h, steps, t_end);
        return;
    }
    FN(operate_first)(m, n, X, Y, Z, U, V, W, h);
    for (int s = 0; s < steps; s++) {
        FN(step_split)
        (m, p, i0, n, X, Y, Z, U, V, W, t + s * h, h, FN(substep_time)(t, h, s + 1, steps, t_end));
        FN(operate_after)(m, n, X, Y, Z, U, V, W, h, s, steps);
    }
}

/* `steps` substeps of h from t on n particles in place, by any scheme. */
static void FN(run_block)(const pfx_motion_plan *m, const PFX_POOL *p, size_t i0, size_t n, R *X,
                          R *Y, R *Z, R *U, R *V, R *W, double t, double h, int steps,
                          double t_end) {
    if (m->scheme == PFX_SCHEME_SPLIT) {
        FN(run_split)(m, p, i0, n, X, Y, Z, U, V, W, t, h, steps, t_end);
        return;
    }
    FN(gd_force) gd;
    const bool fused = FN(gd_setup)(m, p, &gd);
    FN(operate_first)(m, n, X, Y, Z, U, V, W, h);
    for (int s = 0; s < steps; s++) {
        double ts = t + s * h;
        switch (m->scheme) {
        case PFX_SCHEME_EULER:
            FN(step_euler)(m, p, i0, n, X, Y, Z, U, V, W, ts, h);
            break;
        case PFX_SCHEME_SYMPLECTIC:
            FN(step_symplectic)(m, p, i0, n, X, Y, Z, U, V, W, ts, h);
            break;
        case PFX_SCHEME_MIDPOINT:
            if (fused)
                FN(gd_midpoint)(gd, n, X, Y, Z, U, V, W, h);
            else
                FN(step_midpoint)(m, p, i0, n, X, Y, Z, U, V, W, ts, h);
            break;
        case PFX_SCHEME_RK4:
            if (fused)
                FN(gd_rk4)(gd, n, X, Y, Z, U, V, W, h);
            else
                FN(step_rk4)(m, p, i0, n, X, Y, Z, U, V, W, ts, h);
            break;
        case PFX_SCHEME_VERLET:
            if (fused)
                FN(gd_verlet)(gd, n, X, Y, Z, U, V, W, h);
            else
                FN(step_verlet)(m, p, i0, n, X, Y, Z, U, V, W, ts, h);
            break;
        case PFX_SCHEME_SPLIT: /* above */
            break;
        }
        FN(operate_after)(m, n, X, Y, Z, U, V, W, h, s, steps);
    }
}

#include "sim/motion_levels_impl.h"

/* Whether n particles may hold a bad state (PFX_MOTION_MAY_BE_BAD), run
 * on a block while it is in the first-level cache. */
CLONES static int FN(may_be_bad)(size_t n, const R *X, const R *Y, const R *Z, const R *U,
                                 const R *V, const R *W) {
    int alarm = 0;
    for (size_t j = 0; j < n; j++)
        alarm |= PFX_MOTION_MAY_BE_BAD(R, fabs, X[j], Y[j], Z[j], U[j], V[j], W[j]);
    return alarm;
}

/* From t by span, the last substep ending at t_end (t + span, or the
 * caller's own end time of the step). With `alarm`, also whether a
 * particle may have ended in a bad state (FN(may_be_bad) of each block). */
static void FN(advance_to)(const pfx_motion_plan *m, PFX_POOL *p, double t, double span,
                           double t_end, int *alarm) {
    const int steps = pfx_motion_substeps_over(m->steps, m->dt, span);
    const double h = span / steps;
    /* per particle for a full step or a part of one (a newborn's): a
     * longer span takes the count for the span */
    const bool by_radius =
        m->radius_top > 0 && (span <= m->dt || pfx_motion_full_step(m->dt, span));
    for (size_t i0 = 0; i0 < p->count; i0 += BLK) {
        size_t n = p->count - i0 < BLK ? p->count - i0 : BLK;
        R *X = p->px + i0, *Y = p->py + i0, *Z = p->pz + i0;
        R *U = p->vx + i0, *V = p->vy + i0, *W = p->vz + i0;
        if (by_radius)
            FN(advance_by_radius)(m, p, i0, n, X, Y, Z, U, V, W, t, span, steps, t_end);
        else
            FN(run_block)(m, p, i0, n, X, Y, Z, U, V, W, t, h, steps, t_end);
        if (alarm)
            *alarm |= FN(may_be_bad)(n, X, Y, Z, U, V, W);
    }
}

void FN(pfx_motion_advance)(const pfx_motion_plan *m, PFX_POOL *p, double t, double span) {
    FN(advance_to)(m, p, t, span, t + span, NULL);
}

bool FN(pfx_motion_move)(const pfx_motion_plan *m, PFX_POOL *p, double t0, double t1) {
    int alarm = 0;
    FN(advance_to)(m, p, t0, t1 - t0, t1, &alarm);
    return alarm != 0;
}

void FN(pfx_motion_step)(const pfx_motion_plan *m, PFX_POOL *p, double t) {
    FN(pfx_motion_advance)(m, p, t, m->dt);
}

#undef BLOCK_ARGS
#undef BLK
#undef CLONES
#undef FN
#undef R
