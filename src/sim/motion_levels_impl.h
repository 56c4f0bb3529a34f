/* Substeps per particle, the sim's half of the `auto` rule per particle
 * (model/motion.c, choose_by_radius; the plan's radius levels). Not a
 * public header: motion_impl.h includes it, for float and for double, with
 * R, FN, BLK and CLONES defined and run_split declared. */

/* The substep level of each particle under the rule per particle (the
 * plan's radius levels, for a full step of dt): the first level k whose
 * radius_r[k] its nearest reach to the attractor in this step passes: its
 * distance r less d = u dt + A dt^2 / 2, u its speed towards the
 * attractor (|v| where a spiral may turn v within the step), A the
 * attractor's largest pull outside radius_r[k] plus the gravities',
 * scaled; the top level runs all `steps`. r - d >= R is tested as r^2 >=
 * (R + d)^2. */
CLONES static bool FN(radius_levels)(const pfx_motion_plan *m, const PFX_POOL *p, size_t i0,
                                     size_t n, const R *X, const R *Y, const R *Z, const R *U,
                                     const R *V, const R *W, unsigned char *lv) {
    const pfx_motion_choice *c = &m->model->choice;
    const R cx = (R)c->radius.center[0], cy = (R)c->radius.center[1], cz = (R)c->radius.center[2],
            dt = (R)m->dt;
    const R grav = (R)(0.5 * c->radius.gravity * m->dt * m->dt);
    const R *gs = p->gravity_scale ? p->gravity_scale + i0 : NULL;
    R r2[BLK], pull[BLK], vdt[BLK];
    /* (separate loops with the choices hoisted, so that each vectorises) */
    if (gs)
        for (size_t j = 0; j < n; j++)
            pull[j] = grav * fabs(gs[j]);
    else
        for (size_t j = 0; j < n; j++)
            pull[j] = grav;
    /* level 0 first: most blocks are far from the attractor, and done */
    const R r0 = (R)m->radius_r[0], peak0 = (R)(0.5 * m->radius_peak[0] * m->dt * m->dt);
    int any = 0;
    if (m->radius_radial) {
        /* r'' = (|v|^2 - v_r^2) / r + a.r/r >= -A: the distance falls no
         * faster than its own approach speed -v_r and the pull allow, so
         * a particle passing at its pericentre counts no |v| dt */
        for (size_t j = 0; j < n; j++) {
            const R dx = X[j] - cx, dy = Y[j] - cy, dz = Z[j] - cz;
            r2[j] = dx * dx + dy * dy + dz * dz;
            const R r = sqrt(r2[j]), in = -(dx * U[j] + dy * V[j] + dz * W[j]) / (r > 0 ? r : 1);
            vdt[j] = (in > 0 ? in : 0) * dt;
        }
    } else {
        for (size_t j = 0; j < n; j++) {
            const R dx = X[j] - cx, dy = Y[j] - cy, dz = Z[j] - cz;
            r2[j] = dx * dx + dy * dy + dz * dz;
            vdt[j] = sqrt(U[j] * U[j] + V[j] * V[j] + W[j] * W[j]) * dt;
        }
    }
    for (size_t j = 0; j < n; j++) {
        const R far = r0 + ((peak0 + pull[j]) + vdt[j]);
        any |= !(r2[j] >= far * far);
    }
    if (!any)
        return false;
    int lk[BLK];
    for (size_t j = 0; j < n; j++)
        lk[j] = 0;
    for (int k = 0; k < m->radius_top; k++) { /* the tests pass from some level on */
        const R rk = (R)m->radius_r[k], pk = (R)(0.5 * m->radius_peak[k] * m->dt * m->dt);
        for (size_t j = 0; j < n; j++) {
            const R far = rk + ((pk + pull[j]) + vdt[j]);
            lk[j] += !(r2[j] >= far * far);
        }
    }
    for (size_t j = 0; j < n; j++)
        lv[j] = (unsigned char)lk[j];
    return true;
}

/* The substeps of level k over a span of at most dt: no longer than the
 * full step's at that level, dt / 2^k (the top level: the count for the
 * span, `steps`). A full step gets 2^k; a newborn's part of a step as few
 * as its part needs, so that one far from the attractor takes one. */
static int FN(level_substeps)(const pfx_motion_plan *m, int k, double span, int steps) {
    return k < m->radius_top ? pfx_motion_substeps_over(1 << k, m->dt, span) : steps;
}

/* Substeps per particle (choice.radius): the block runs in place at its
 * lowest level; the particles that need more are saved first, then run
 * again from their start at their own level and written back. Each
 * particle's result depends on its own state and the span alone, whatever
 * block or thread it is in. The levels are those of a full step (its reach
 * and radii), which hold a fortiori over a shorter span with substeps no
 * longer than the full step's. */
static void FN(advance_by_radius)(const pfx_motion_plan *m, const PFX_POOL *p, size_t i0, size_t n,
                                  R *X, R *Y, R *Z, R *U, R *V, R *W, double t, double span,
                                  int steps, double t_end) {
    unsigned char lv[BLK];
    const int top = m->radius_top;
    if (!FN(radius_levels)(m, p, i0, n, X, Y, Z, U, V, W, lv)) { /* all at level 0 */
        const int n0 = FN(level_substeps)(m, 0, span, steps);
        FN(run_split)(m, p, i0, n, X, Y, Z, U, V, W, t, span / n0, n0, t_end);
        return;
    }
    int lo = top, hi = 0;
    for (size_t j = 0; j < n; j++) {
        lo = lv[j] < lo ? lv[j] : lo;
        hi = lv[j] > hi ? lv[j] : hi;
    }
    /* the saved particles' start states and columns, then one level's */
    R sv[7][BLK], q[7][BLK];
    unsigned short at[BLK];
    const R *gs = p->gravity_scale ? p->gravity_scale + i0 : NULL;
    R *const cols[6] = {X, Y, Z, U, V, W};
    size_t saved = 0;
    for (size_t j = 0; j < n && lo < hi; j++)
        if (lv[j] > lo) {
            for (int c = 0; c < 6; c++)
                sv[c][saved] = cols[c][j];
            sv[6][saved] = gs ? gs[j] : (R)1;
            at[saved++] = (unsigned short)j;
        }
    const int n_lo = FN(level_substeps)(m, lo, span, steps);
    FN(run_split)(m, p, i0, n, X, Y, Z, U, V, W, t, span / n_lo, n_lo, t_end);
    for (int k = lo + 1; k <= hi; k++) {
        size_t cnt = 0;
        unsigned short back[BLK];
        for (size_t s = 0; s < saved; s++)
            if (lv[at[s]] == k) {
                for (int c = 0; c < 7; c++)
                    q[c][cnt] = sv[c][s];
                back[cnt++] = at[s];
            }
        if (!cnt)
            continue;
        PFX_POOL one = {.count = cnt, .gravity_scale = gs ? q[6] : NULL};
        const int nk = FN(level_substeps)(m, k, span, steps);
        FN(run_split)(m, &one, 0, cnt, q[0], q[1], q[2], q[3], q[4], q[5], t, span / nk, nk, t_end);
        for (size_t s = 0; s < cnt; s++)
            for (int c = 0; c < 6; c++)
                cols[c][back[s]] = q[c][s];
    }
}
