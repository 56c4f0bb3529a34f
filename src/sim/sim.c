/* The fixed-step simulation of pfx_sim.h. Per step and emitter, one pass
 * each: integrate the live particles, remove the dead by swap-remove, then
 * emit the births due in the step at their exact times. It allocates only
 * in pfx_sim_create. Gravity is the only force here: with a constant
 * acceleration the update x += v dt + a dt^2/2, v += a dt is exact. */
#include "sim/sim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/birth.h"
#include "sim/kill.h"
#include "sim/sample.h"
#include "sim/schedule.h"
#include "sim/spawn.h"

/* Swap-remove and copies treat a pool as a list of columns of 4-byte (float,
 * uint32_t) or 1-byte (flag) elements, moved with memcpy: writing a float
 * column through a uint32_t pointer would break strict aliasing (the
 * optimiser then keeps stale ages in registers). */
#define MAX_COLUMNS 28
typedef struct column_list {
    unsigned char *col[MAX_COLUMNS];
    size_t size[MAX_COLUMNS];
    int count;
} column_list;

static void add_column(column_list *c, void *col, size_t size) {
    if (col) {
        c->col[c->count] = col;
        c->size[c->count++] = size;
    }
}

static column_list pool_columns(const pfx_pool *p) {
    column_list c = {.count = 0};
    add_column(&c, p->birth, 8);
    void *four[] = {p->px,         p->py,     p->pz,
                    p->vx,         p->vy,     p->vz,
                    p->lifetime,   p->id,     p->gravity_scale,
                    p->size0,      p->size1,  p->charge,
                    p->mass,       p->bx,     p->by,
                    p->bz,         p->tint,   p->generation,
                    p->pr,         p->pg,     p->pb,
                    p->size_scale, p->angle0, p->spin};
    for (size_t k = 0; k < sizeof four / sizeof *four && c.count < MAX_COLUMNS; k++)
        add_column(&c, four[k], 4);
    add_column(&c, p->stuck, 1);
    return c;
}

/* Lays out the float columns emitter em needs: each takes n floats from
 * base (when base is NULL only the count is wanted). Returns the floats per
 * particle. The one place that decides which columns exist, so the size
 * pfx_info reports and the allocation cannot disagree. */
static size_t layout_columns(const pfx_emitter *em, pfx_pool *p, float *base, uint32_t n) {
    size_t used = 0;
#define TAKE(field, cond)                                                                          \
    do {                                                                                           \
        if (cond) {                                                                                \
            if (base)                                                                              \
                p->field = (void *)(base + used * n);                                              \
            used++;                                                                                \
        }                                                                                          \
    } while (0)
    /* The birth time first: a double, two float slots, 8-byte aligned
     * because every pool starts on an even float (see pfx_sim_create). */
    if (base)
        p->birth = (double *)(void *)base;
    used += 2;
    TAKE(px, true);
    TAKE(py, true);
    TAKE(pz, true);
    TAKE(vx, true);
    TAKE(vy, true);
    TAKE(vz, true);
    TAKE(lifetime, true);
    TAKE(id, true);
    TAKE(gravity_scale, pfx_needs_gravity_scale(em));
    TAKE(size0, pfx_needs_size0(em));
    TAKE(size1, pfx_needs_size1(em));
    TAKE(charge, pfx_needs_charge(em));
    TAKE(mass, pfx_needs_mass(em));
    TAKE(tint, pfx_needs_tint(em));
    TAKE(angle0, pfx_needs_angle(em));
    TAKE(spin, pfx_needs_spin(em));
    TAKE(generation, em->keeps_generation);
    TAKE(pr, em->keeps_parent_color);
    TAKE(pg, em->keeps_parent_color);
    TAKE(pb, em->keeps_parent_color);
    TAKE(size_scale, em->keeps_size_scale);
    TAKE(bx, pfx_needs_birth(em));
    TAKE(by, pfx_needs_birth(em));
    TAKE(bz, pfx_needs_birth(em));
    for (int k = 0; k < 6; k++)
        TAKE(start[k], em->deflector_count > 0);
#undef TAKE
    return used;
}

/* Floats a pool of n particles takes, rounded up to even so the next
 * pool's age column stays 8-byte aligned. */
static size_t pool_floats(const pfx_emitter *em, uint32_t n) {
    pfx_pool unused;
    size_t f = layout_columns(em, &unused, NULL, 1) * n;
    return f + (f & 1);
}

size_t pfx_sim_bytes_per_particle(const pfx_effect *e, size_t i) {
    const pfx_emitter *em = &e->emitters[i];
    pfx_pool unused;
    return 4 * layout_columns(em, &unused, NULL, 1) + em->sticks;
}

/* Seeds every emitter's streams and schedule: the state at time 0. */
static void init_emitters(pfx_sim *s) {
    const pfx_effect *e = s->effect;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        pfx_emitter_state *st = &s->emitters[i];
        memset(st, 0, sizeof *st);
        uint64_t stream = pfx_rng_stream_for(em->name);
        pfx_rng_seed(&st->rng, e->seed, stream);
        st->rng_base = st->rng;
        pfx_rng probe = st->rng;
        birth_draws b;
        pfx_birth_draw(em, 0, &probe, NULL, NULL, &b);
        st->draws_per_birth = probe.draws - st->rng.draws;
        pfx_schedule_init(&st->sched, em, e->seed, stream);
        pfx_rng_seed(&st->collide_rng, e->seed, stream ^ 0xc011deULL);
        pfx_rng_seed(&st->spawn_rng, e->seed, stream ^ 0x5ba3ULL);
    }
}

pfx_sim *pfx_sim_create(const pfx_effect *e) {
    pfx_sim *s = calloc(1, sizeof *s);
    if (!s)
        return NULL;
    s->effect = e;
    s->dt = 1.0 / e->sim_rate;
    s->pools = calloc(e->emitter_count + 1, sizeof *s->pools);
    s->emitters = calloc(e->emitter_count + 1, sizeof *s->emitters);
    s->plans = calloc(e->emitter_count + 1, sizeof *s->plans);
    size_t bytes = 0;
    for (size_t i = 0; i < e->emitter_count; i++)
        bytes += 4 * pool_floats(&e->emitters[i], e->emitters[i].capacity) +
                 (size_t)e->emitters[i].sticks * e->emitters[i].capacity;
    s->storage = malloc(bytes ? bytes : 1);
    if (!s->pools || !s->emitters || !s->plans || !s->storage || !pfx_spawn_queues_create(s)) {
        pfx_sim_destroy(s);
        return NULL;
    }
    s->bytes = bytes;
    float *next = s->storage;
    /* Flag columns (1 byte) go after every float column, keeping those aligned. */
    unsigned char *flags = (unsigned char *)s->storage;
    for (size_t i = 0; i < e->emitter_count; i++)
        flags += 4 * pool_floats(&e->emitters[i], e->emitters[i].capacity);
    for (size_t i = 0; i < e->emitter_count; i++)
        if (e->emitters[i].sticks) {
            s->pools[i].stuck = flags;
            flags += e->emitters[i].capacity;
        }
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        pfx_pool *p = &s->pools[i];
        uint32_t n = em->capacity;
        p->capacity = n;
        layout_columns(em, p, next, n);
        next += pool_floats(em, n);
        if (em->motion)
            pfx_motion_plan_init(&s->plans[i], em->motion);
    }
    init_emitters(s);
    return s;
}

void pfx_sim_reset(pfx_sim *s) {
    const pfx_effect *e = s->effect;
    for (size_t i = 0; i < e->emitter_count; i++)
        s->pools[i].count = 0, s->pools[i].time = 0, s->pools[i].may_run_away = false;
    init_emitters(s);
    s->step = 0;
    s->time = 0;
    s->failed = false;
}

void pfx_sim_destroy(pfx_sim *s) {
    if (!s)
        return;
    free(s->storage);
    free(s->pools);
    free(s->emitters);
    free(s->plans);
    pfx_spawn_queues_destroy(s);
    pfx_sim_destroy(s->loop_start);
    free(s);
}

/* The exact constant-acceleration step of particles [0, n), x += v dt + a
 * dt^2/2, v += a dt, with the per-emitter acceleration hoisted, or a per
 * particle gravity_scale g times it. With `check` it also returns whether
 * some particle may be non-finite or runaway: a branch-free OR over
 * per-component tests (|v_c| > 1e6/sqrt(3), |x_c| > 1e7 or NaN), for
 * check_state to confirm. Always inlined with a constant `check`, so the
 * loop without it has no compares at all. */
static inline __attribute__((always_inline)) bool
gravity_step(uint32_t n, float *restrict px, float *restrict py, float *restrict pz,
             float *restrict vx, float *restrict vy, float *restrict vz, const float *restrict gs,
             const float a[3], float dt, const bool check) {
    const float h = 0.5f * dt * dt, vlim = 5.7e5f, xlim = (float)PFX_MOTION_MAX_POSITION;
    const float ax = a[0], ay = a[1], az = a[2];
    int alarm = 0;
    for (uint32_t i = 0; i < n; i++) {
        const float g = gs ? gs[i] : 1.0f;
        px[i] += vx[i] * dt + g * ax * h;
        py[i] += vy[i] * dt + g * ay * h;
        pz[i] += vz[i] * dt + g * az * h;
        vx[i] += g * ax * dt;
        vy[i] += g * ay * dt;
        vz[i] += g * az * dt;
        if (check)
            alarm |= !(fabsf(vx[i]) <= vlim) | !(fabsf(vy[i]) <= vlim) | !(fabsf(vz[i]) <= vlim) |
                     !(fabsf(px[i]) <= xlim) | !(fabsf(py[i]) <= xlim) | !(fabsf(pz[i]) <= xlim);
    }
    return alarm;
}

/* Exact constant-acceleration motion over dt for every live particle of a
 * gravity-only emitter. Ages need no update: the pool keeps birth times.
 * The state check rides along only when some particle's bound at birth
 * could reach it (pool->may_run_away); otherwise the state provably stays
 * finite and in range and the loop is the bare update. Returns whether the
 * check saw something. */
static bool integrate_gravity(const pfx_emitter *em, pfx_pool *p, float dt) {
    float *px = p->px, *py = p->py, *pz = p->pz, *vx = p->vx, *vy = p->vy, *vz = p->vz;
    if (!p->gravity_scale) {
        /* The scale folded into the acceleration: one multiply-add chain. */
        const double gs = em->gravity_scale.a;
        const float a[3] = {(float)(em->accel[0] * gs), (float)(em->accel[1] * gs),
                            (float)(em->accel[2] * gs)};
        return p->may_run_away ? gravity_step(p->count, px, py, pz, vx, vy, vz, NULL, a, dt, true)
                               : gravity_step(p->count, px, py, pz, vx, vy, vz, NULL, a, dt, false);
    }
    const float a[3] = {(float)em->accel[0], (float)em->accel[1], (float)em->accel[2]};
    const float *gs = p->gravity_scale;
    return p->may_run_away ? gravity_step(p->count, px, py, pz, vx, vy, vz, gs, a, dt, true)
                           : gravity_step(p->count, px, py, pz, vx, vy, vz, gs, a, dt, false);
}

/* Whether a newborn of a gravity-only emitter could ever trip the state
 * check: under a constant acceleration a its speed stays within |v| + |a| L
 * for its lifetime L (a bounce takes speed away: resilience and friction
 * are at most 1; wrapping only moves it back), and its distance from the
 * origin within |x| + that speed times L. */
static bool may_run_away(const float x[3], const float v[3], const double a[3], double life) {
    double speed = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]) +
                   sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) * life;
    double far =
        sqrt((double)x[0] * x[0] + (double)x[1] * x[1] + (double)x[2] * x[2]) + speed * life;
    return !(speed < 5.7e5 && far < 0.5 * PFX_MOTION_MAX_POSITION);
}

static pfx_motion_pool_f motion_view(const pfx_pool *p, uint32_t first, uint32_t n) {
    return (pfx_motion_pool_f){.count = n,
                               .px = p->px + first,
                               .py = p->py + first,
                               .pz = p->pz + first,
                               .vx = p->vx + first,
                               .vy = p->vy + first,
                               .vz = p->vz + first,
                               .gravity_scale = p->gravity_scale ? p->gravity_scale + first : NULL,
                               .charge = p->charge ? p->charge + first : NULL,
                               .mass = p->mass ? p->mass + first : NULL,
                               .bx = p->bx ? p->bx + first : NULL,
                               .by = p->by ? p->by + first : NULL,
                               .bz = p->bz ? p->bz + first : NULL};
}

/* The state check: the first of particles [first, count) of emitter i that
 * is non-finite, faster than 1e6 m/s or farther than 1e7 m stops the
 * simulation, naming the emitter, the particle, the time and the stability
 * warning that predicted it. Every particle passes it after every step,
 * its birth step included. */
static void check_state(pfx_sim *s, size_t i, uint32_t first, double t) {
    const pfx_pool *p = &s->pools[i];
    if (s->failed || first >= p->count)
        return;
    pfx_motion_pool_f view = motion_view(p, first, p->count - first);
    pfx_bad_kind why;
    size_t bad = pfx_motion_find_bad_f(&view, &why);
    if (bad == view.count)
        return;
    const pfx_emitter *em = &s->effect->emitters[i];
    char cause[320];
    if (em->motion)
        pfx_motion_blame(em->motion, why, cause, sizeof cause);
    else
        snprintf(cause, sizeof cause, "the emitter's speeds, gravity and lifetimes are too large");
    s->failed = true;
    snprintf(s->error, sizeof s->error,
             "emitter '%s': particle %u became %s at t = %.4g s; likely cause: %s", em->name,
             p->id[first + bad],
             why == PFX_BAD_NONFINITE ? "non-finite"
             : why == PFX_BAD_SPEED   ? "faster than 1e6 m/s"
                                      : "farther than 1e7 m",
             t, cause);
}

/* Any other force set: the emitter's motion model, prepared once for the
 * fixed step; a view's remainder runs the same scheme in substeps no longer
 * than the prepared ones (pfx_motion_advance_f), never a re-chosen one. */
static void integrate_motion(pfx_sim *s, size_t i, double span) {
    pfx_pool *p = &s->pools[i];
    pfx_motion_pool_f view = motion_view(p, 0, p->count);
    pfx_motion_advance_f(&s->plans[i], &view, s->time, span);
}

/* The start-of-step state the collision pass sweeps from. */
static void save_start(pfx_pool *p) {
    float *cols[6] = {p->px, p->py, p->pz, p->vx, p->vy, p->vz};
    for (int k = 0; k < 6; k++)
        memcpy(p->start[k], cols[k], p->count * sizeof(float));
}

/* A deflector hit of particle `first + index` becomes an on_hit event at
 * the exact time and place, with the surface normal. */
typedef struct hit_context {
    pfx_sim *s;
    size_t emitter;
    uint32_t first;
    double t0;
} hit_context;

static void on_hit(void *user, uint32_t index, size_t deflector, const double pos[3],
                   const double normal[3], double t_hit) {
    (void)deflector;
    hit_context *h = user;
    const pfx_pool *p = &h->s->pools[h->emitter];
    uint32_t j = h->first + index;
    const double vel[3] = {p->vx[j], p->vy[j], p->vz[j]};
    pfx_spawn_event_of(h->s, h->emitter, PFX_SPAWN_HIT, j, h->t0 + t_hit, pos, vel, normal);
}

/* Deflectors for particles [first, first + n) over the step of length dt
 * just integrated: each path is swept from its start state, so nothing
 * tunnels, and hits are resolved at their exact times (src/sim/collide.c). */
static void collide(pfx_sim *s, size_t i, uint32_t first, uint32_t n, double t0, double dt) {
    const pfx_emitter *em = &s->effect->emitters[i];
    pfx_pool *p = &s->pools[i];
    pfx_emitter_state *st = &s->emitters[i];
    pfx_collide_pool view = {.count = n,
                             .px0 = p->start[0] + first,
                             .py0 = p->start[1] + first,
                             .pz0 = p->start[2] + first,
                             .vx0 = p->start[3] + first,
                             .vy0 = p->start[4] + first,
                             .vz0 = p->start[5] + first,
                             .px = p->px + first,
                             .py = p->py + first,
                             .pz = p->pz + first,
                             .vx = p->vx + first,
                             .vy = p->vy + first,
                             .vz = p->vz + first,
                             .lifetime = p->lifetime + first,
                             .id = p->id + first,
                             .stuck = p->stuck ? p->stuck + first : NULL};
    hit_context hc = {s, i, first, t0};
    bool hits = em->spawn_count && pfx_spawn_has(em, PFX_SPAWN_HIT);
    pfx_collide(em->deflectors, em->deflector_count, dt, &view, &st->collide_rng,
                hits ? on_hit : NULL, &hc, &st->collisions);
}

/* Death at age >= lifetime; the last live particle fills the hole. */
static void kill_expired(pfx_sim *s, size_t emitter, double t1) {
    pfx_pool *p = &s->pools[emitter];
    const bool deaths = pfx_spawn_has(&s->effect->emitters[emitter], PFX_SPAWN_DEATH);
    column_list c = pool_columns(p);
    const double *birth = p->birth;
    const float *lifetime = p->lifetime;
    /* Most blocks hold no death: a branch-free scan (vectorised) skips them,
     * and only a block with a death runs the swap-remove loop. */
    enum { BLOCK = 64 };
    uint32_t i = 0;
    while (i < p->count) {
        uint32_t end = p->count - i > BLOCK ? i + BLOCK : p->count;
        int dead = 0;
        for (uint32_t j = i; j < end; j++)
            dead |= t1 - birth[j] >= lifetime[j];
        if (!dead) {
            i = end;
            continue;
        }
        while (i < end) {
            if (t1 - birth[i] < lifetime[i]) {
                i++;
                continue;
            }
            if (deaths) {
                /* Died at t1 - (age - lifetime), back along its velocity;
                 * killed ones (PFX_KILLED) at t1, where they are. */
                double over = p->lifetime[i] < 0 ? 0 : (t1 - birth[i]) - p->lifetime[i];
                const double pos[3] = {p->px[i] - p->vx[i] * over, p->py[i] - p->vy[i] * over,
                                       p->pz[i] - p->vz[i] * over},
                             vel[3] = {p->vx[i], p->vy[i], p->vz[i]};
                pfx_spawn_event_of(s, emitter, PFX_SPAWN_DEATH, i, t1 - over, pos, vel, NULL);
            }
            uint32_t last = --p->count;
            for (int k = 0; k < c.count; k++)
                memcpy(c.col[k] + c.size[k] * i, c.col[k] + c.size[k] * last, c.size[k]);
            if (end > p->count)
                end = p->count;
        }
    }
}

bool pfx_sim_make_particle(pfx_sim *s, size_t i, double tb, double t1, const pfx_parent *parent) {
    const pfx_emitter *em = &s->effect->emitters[i];
    pfx_emitter_state *st = &s->emitters[i];
    pfx_pool *p = &s->pools[i];
    uint64_t k = st->born++;
    double age = t1 - tb;
    if (p->count == p->capacity || age >= em->max_lifetime) {
        st->dropped += p->count == p->capacity && age < em->max_lifetime;
        pfx_rng_advance(&st->rng, st->draws_per_birth);
        return false;
    }
    birth_draws b;
    pfx_birth_draw(em, tb, &st->rng, parent ? parent->pos : NULL,
                   parent && parent->has_normal ? parent->normal : NULL, &b);
    if (parent && parent->inherit_velocity)
        for (int a = 0; a < 3; a++)
            b.vel[a] += parent->vel[a];
    if (age >= b.life)
        return false; /* would already be dead: never created */
    uint32_t j = p->count++;
    p->px[j] = (float)b.pos[0], p->py[j] = (float)b.pos[1], p->pz[j] = (float)b.pos[2];
    p->vx[j] = (float)b.vel[0], p->vy[j] = (float)b.vel[1], p->vz[j] = (float)b.vel[2];
    p->birth[j] = tb;
    p->lifetime[j] = (float)b.life;
    p->id[j] = (uint32_t)k;
    if (p->gravity_scale)
        p->gravity_scale[j] = (float)b.gs;
    if (p->size0)
        p->size0[j] = (float)b.s0;
    if (p->size1)
        p->size1[j] = (float)b.s1;
    if (p->charge)
        p->charge[j] = (float)b.q;
    if (p->mass)
        p->mass[j] = (float)b.mass;
    if (p->bx)
        p->bx[j] = (float)b.pos[0], p->by[j] = (float)b.pos[1], p->bz[j] = (float)b.pos[2];
    if (p->stuck)
        p->stuck[j] = 0;
    if (p->tint)
        p->tint[j] = (float)b.tint;
    if (p->angle0)
        p->angle0[j] = (float)b.angle;
    if (p->spin)
        p->spin[j] = (float)b.spin;
    if (p->generation)
        p->generation[j] = parent ? parent->generation + 1 : 0;
    if (p->pr) {
        bool inherit = parent && parent->inherit_color;
        p->pr[j] = inherit ? parent->color[0] : 1;
        p->pg[j] = inherit ? parent->color[1] : 1;
        p->pb[j] = inherit ? parent->color[2] : 1;
    }
    if (p->size_scale)
        p->size_scale[j] = parent && parent->inherit_size ? parent->size : 1;
    const double v0[3] = {b.vel[0], b.vel[1], b.vel[2]};
    if (age > 0) {
        /* The rest of the step after the birth, by the emitter's own method:
         * the state stored at birth is stepped over `age` exactly as a
         * particle started alone at tb would be (the same scheme, substeps
         * no longer than the full step's, operators included). Gravity
         * alone is the constant-acceleration closed form, in double. */
        if (em->deflector_count)
            for (int a = 0; a < 3; a++) {
                p->start[a][j] = (float)b.pos[a];
                p->start[3 + a][j] = (float)b.vel[a];
            }
        if (em->motion) {
            pfx_motion_pool_f one = motion_view(p, j, 1);
            pfx_motion_advance_f(&s->plans[i], &one, tb, age);
        } else {
            float *x[3] = {p->px, p->py, p->pz}, *v[3] = {p->vx, p->vy, p->vz};
            for (int a = 0; a < 3; a++) {
                double acc = em->accel[a] * b.gs, x0 = x[a][j], u0 = v[a][j];
                x[a][j] = (float)(x0 + u0 * age + 0.5 * acc * age * age);
                v[a][j] = (float)(u0 + acc * age);
            }
        }
    }
    if (!em->motion && !p->may_run_away) {
        const float x[3] = {p->px[j], p->py[j], p->pz[j]}, v[3] = {p->vx[j], p->vy[j], p->vz[j]};
        const double a[3] = {em->accel[0] * b.gs, em->accel[1] * b.gs, em->accel[2] * b.gs};
        p->may_run_away = may_run_away(x, v, a, b.life);
    }
    if (age > 0) {
        /* The newborn's partial step is swept like a full one. */
        if (em->deflector_count)
            collide(s, i, j, 1, tb, age);
        if (em->spawn_count && pfx_spawn_has(em, PFX_SPAWN_TRAIL))
            pfx_spawn_trails(s, i, j, 1, tb, t1);
    }
    if (em->spawn_count)
        pfx_spawn_event_of(s, i, PFX_SPAWN_BIRTH, j, tb, b.pos, v0, NULL);
    return true;
}

/* A looping effect draws the same values in every period: at a period's
 * first birth the attribute stream starts over. */
static void repeat_draws(pfx_sim *s, size_t i) {
    pfx_emitter_state *st = &s->emitters[i];
    if (s->effect->loop && st->sched.period != st->rng_period) {
        st->rng = st->rng_base;
        st->rng_period = st->sched.period;
    }
}

/* Emits the scheduled births due up to t1. Births that cannot be alive at
 * t1 (older than the maximum lifetime) are skipped in closed form where the
 * rate allows and their draws jumped over, so a step's cost is bounded by
 * the births due in it, whatever they are. */
static void emit(pfx_sim *s, size_t i, double t1) {
    const pfx_emitter *em = &s->effect->emitters[i];
    pfx_emitter_state *st = &s->emitters[i];
    const pfx_pool *p = &s->pools[i];
    for (;;) {
        repeat_draws(s, i);
        /* Births at least a maximum lifetime old are dead at t1, and when
         * the pool is full none of the step's births can be kept: both are
         * passed over in bulk (bursts whole, rates in closed form), their
         * draws jumped, so no rate or burst size can make a step slow. */
        uint64_t n = pfx_schedule_drop_until(&st->sched, em, t1 - em->max_lifetime);
        if (!n && p->count == p->capacity) {
            n = pfx_schedule_drop_until(&st->sched, em, t1);
            st->dropped += n;
        }
        if (n) {
            pfx_rng_advance(&st->rng, n * st->draws_per_birth);
            st->born += n;
            continue;
        }
        double tb = pfx_schedule_peek(&st->sched, em);
        if (!(tb <= t1))
            break;
        pfx_schedule_pop(&st->sched, em);
        pfx_sim_make_particle(s, i, tb, t1, NULL);
    }
}

/* A view of p's particles from index `from` on (same columns, shifted). */
static void offset_pool(pfx_pool *p, uint32_t from) {
    p->birth += from;
    float **f[] = {&p->px,         &p->py,     &p->pz,       &p->vx,
                   &p->vy,         &p->vz,     &p->lifetime, &p->gravity_scale,
                   &p->size0,      &p->size1,  &p->charge,   &p->mass,
                   &p->bx,         &p->by,     &p->bz,       &p->tint,
                   &p->generation, &p->pr,     &p->pg,       &p->pb,
                   &p->size_scale, &p->angle0, &p->spin};
    for (size_t k = 0; k < sizeof f / sizeof *f; k++)
        if (*f[k])
            *f[k] += from;
    p->id += from;
    if (p->stuck)
        p->stuck += from;
    p->count -= from;
    p->capacity -= from;
}

/* Advances every emitter from s->time to t1. Per emitter: integrate (the
 * state check sees every particle), deflectors, trails (before deaths, so a
 * particle lays every trail birth of its last step), kill rules, deaths,
 * then the births due, each stepped from its birth time. */
static void advance(pfx_sim *s, double t1) {
    const pfx_effect *e = s->effect;
    const double t0 = s->time;
    const float dt = (float)(t1 - t0);
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        pfx_pool *p = &s->pools[i];
        if (dt > 0) {
            if (em->deflector_count)
                save_start(p);
            bool alarm = true;
            if (em->motion)
                integrate_motion(s, i, t1 - t0);
            else
                alarm = integrate_gravity(em, p, dt);
            p->time = t1;
            if (alarm)
                check_state(s, i, 0, t1);
            if (em->deflector_count)
                collide(s, i, 0, p->count, t0, dt);
            if (em->spawn_count && pfx_spawn_has(em, PFX_SPAWN_TRAIL))
                pfx_spawn_trails(s, i, 0, p->count, t0, t1);
            if (em->kill) {
                emitter_pose pose;
                pfx_emitter_pose_at(em, t1, &pose);
                pfx_kill_apply(em->kill, p, pose.position, em->alpha_at_age);
            }
            kill_expired(s, i, t1);
        }
        p->time = t1;
        p->newborn = p->count;
        emit(s, i, t1);
    }
    /* Sub-emitter births after every emitter has moved: file order does not
     * matter. */
    pfx_spawn_process(s, t1);
    /* Particles born in this step met their deflectors (a kill marks them
     * PFX_KILLED) and must meet the kill rules and the state check before
     * anyone sees them. */
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        pfx_pool *p = &s->pools[i];
        check_state(s, i, p->newborn, t1);
        if (p->count <= p->newborn || (!em->kill && !em->deflector_count))
            continue;
        if (em->kill) {
            pfx_pool born = *p;
            offset_pool(&born, p->newborn);
            emitter_pose pose;
            pfx_emitter_pose_at(em, t1, &pose);
            pfx_kill_apply(em->kill, &born, pose.position, em->alpha_at_age);
        }
        kill_expired(s, i, t1);
    }
    s->time = t1;
}

void pfx_sim_step(pfx_sim *s) {
    if (s->failed)
        return;
    s->step++;
    advance(s, (double)s->step / s->effect->sim_rate);
}

void pfx_sim_run_to(pfx_sim *s, double t) {
    const double rate = s->effect->sim_rate;
    /* Compare in steps: (step + 1) <= t * rate, with a tolerance for a time
     * that is a whole number of steps but not exactly representable. */
    while (!s->failed && (double)(s->step + 1) <= t * rate + 1e-7)
        pfx_sim_step(s);
}

void pfx_sim_view_at(const pfx_sim *s, pfx_sim *view, double t) {
    const pfx_effect *e = s->effect;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_pool *src = &s->pools[i];
        pfx_pool *dst = &view->pools[i];
        column_list a = pool_columns(src), b = pool_columns(dst);
        for (int k = 0; k < a.count; k++)
            memcpy(b.col[k], a.col[k], src->count * a.size[k]);
        dst->count = src->count;
        dst->time = src->time;
        dst->may_run_away = src->may_run_away;
        view->emitters[i] = s->emitters[i];
    }
    view->step = s->step;
    view->time = s->time;
    if (t > s->time + 1e-12)
        advance(view, t);
}

double pfx_sim_frame_time(const pfx_effect *e, long frame) {
    /* A looping effect shows one period, from a time when every particle
     * alive belongs to the periodic regime: frame f is frame f mod N, so
     * frame N is frame 0 byte for byte. */
    if (e->loop)
        return e->loop_start + (double)(frame % e->loop_frames) / e->fps;
    return e->prewarm + (double)frame / e->fps;
}

/* The lookup-table entry for normalised age (or any u in [0, 1]): nearest. */
static int lut_index(float u) {
    int k = (int)(u * (PFX_GRADIENT_LUT - 1) + 0.5f);
    return k < 0 ? 0 : k >= PFX_GRADIENT_LUT ? PFX_GRADIENT_LUT - 1 : k;
}

float pfx_particle_size(const pfx_emitter *em, const pfx_pool *p, uint32_t i) {
    float u = (float)pfx_particle_age(p, i) / p->lifetime[i];
    float scale = p->size_scale ? p->size_scale[i] : 1.0f;
    if (em->size_curve)
        return em->size_lut[lut_index(u)] * scale;
    float s0 = p->size0 ? p->size0[i] : (float)em->size_start.a;
    float s1 = p->size1 ? p->size1[i] : em->size_same ? s0 : (float)em->size_end.a;
    return (s0 + (s1 - s0) * u) * scale;
}

void pfx_particle_color(const pfx_emitter *em, const pfx_pool *p, uint32_t i, float out[4]) {
    int k = lut_index((float)pfx_particle_age(p, i) / p->lifetime[i]);
    switch (em->color_mode) {
    case PFX_COLOR_RANDOM: {
        float t = p->tint[i];
        for (int c = 0; c < 4; c++)
            out[c] = em->color_a[c] + (em->color_b[c] - em->color_a[c]) * t;
        break;
    }
    case PFX_COLOR_PICK:
        memcpy(out, em->color.lut[lut_index(p->tint[i])], 4 * sizeof(float));
        break;
    default:
        memcpy(out, em->color.lut[k], 4 * sizeof(float));
    }
    if (em->alpha_curve)
        out[3] *= em->alpha_lut[k];
    if (p->pr) {
        out[0] *= p->pr[i];
        out[1] *= p->pg[i];
        out[2] *= p->pb[i];
    }
}

float pfx_particle_angle(const pfx_emitter *em, const pfx_pool *p, uint32_t i) {
    const float age = (float)pfx_particle_age(p, i);
    float a0 = p->angle0 ? p->angle0[i] : (float)em->angle.a;
    float turned = em->spin_curve
                       ? p->lifetime[i] * em->spin_turn_lut[lut_index(age / p->lifetime[i])]
                       : (p->spin ? p->spin[i] : (float)em->spin.a) * age;
    return (a0 + turned) * (float)(M_PI / 180);
}

uint64_t pfx_sim_hash(const pfx_sim *s) {
    uint64_t h = 1469598103934665603ULL;
    for (size_t i = 0; i < s->effect->emitter_count; i++) {
        const pfx_pool *p = &s->pools[i];
        column_list c = pool_columns(p);
        for (int k = 0; k < c.count; k++) {
            const unsigned char *b = (const unsigned char *)c.col[k];
            for (size_t j = 0; j < (size_t)p->count * c.size[k]; j++) {
                h ^= b[j];
                h *= 1099511628211ULL;
            }
        }
        h ^= p->count;
        h *= 1099511628211ULL;
    }
    return h;
}

const pfx_sim *pfx_sim_frame(pfx_sim *s, pfx_sim *view, long frame) {
    double t = pfx_sim_frame_time(s->effect, frame);
    if (t < s->time - 1e-12) {
        /* A looping effect wrapped round: back to frame 0's state (kept when
         * first reached), not to time 0 and its whole warm-up again. */
        if (s->loop_start)
            pfx_sim_view_at(s->loop_start, s, s->loop_start->time);
        else
            pfx_sim_reset(s);
    }
    pfx_sim_run_to(s, t);
    if (s->effect->loop && !s->loop_start && frame % s->effect->loop_frames == 0 &&
        (s->loop_start = pfx_sim_create(s->effect)))
        pfx_sim_view_at(s, s->loop_start, s->time);
    if (s->step == 0 && t <= s->time + 1e-12) {
        /* Births at exactly time 0 (a burst at 0) belong to frame 0, but no
         * step has ended there yet: a step of length zero emits them. */
        pfx_sim_view_at(s, view, s->time);
        advance(view, s->time);
        return view;
    }
    if (t <= s->time + 1e-12)
        return s;
    pfx_sim_view_at(s, view, t);
    return view;
}
