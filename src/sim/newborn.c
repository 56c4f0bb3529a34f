/* Births: every new particle, scheduled or from a sub-emitter event, is
 * drawn, written into its emitter's pool and stepped from its birth time to
 * the end of the step by the emitter's own method (with its deflectors,
 * trail and on_birth events). Scheduled births come in time order from the
 * emitter's schedule; sub-emitter births from the queues of spawn.c. */
#include "sim/newborn.h"

#include <math.h>
#include <string.h>

#include "sim/birth.h"
#include "sim/sample.h"
#include "sim/schedule.h"
#include "sim/spawn.h"
#include "sim/step.h"

/* Writes the newborn's drawn state into row j of pool p, column by
 * column: only the columns the pool has (the emitter's features decide
 * which); what a parent passes on (colour, size, generation, id) comes from
 * `parent`, else the defaults. k is the particle's birth number, its id. */
static void write_newborn(pfx_pool *p, uint32_t j, const birth_draws *b, uint64_t k, double tb,
                          const pfx_parent *parent) {
    p->px[j] = (float)b->pos[0], p->py[j] = (float)b->pos[1], p->pz[j] = (float)b->pos[2];
    p->vx[j] = (float)b->vel[0], p->vy[j] = (float)b->vel[1], p->vz[j] = (float)b->vel[2];
    if (p->ax) /* its partial step keeps none: the first full step evaluates it */
        p->ax[j] = NAN;
    if (p->rest) /* awake: its first full step is swept */
        p->rest[j] = 0;
    p->birth[j] = tb;
    p->lifetime[j] = (float)b->life;
    p->id[j] = (uint32_t)k;
    if (p->gravity_scale)
        p->gravity_scale[j] = (float)b->gs;
    if (p->size0)
        p->size0[j] = (float)b->s0;
    if (p->size1)
        p->size1[j] = (float)b->s1;
    if (p->charge)
        p->charge[j] = (float)b->q;
    if (p->mass)
        p->mass[j] = (float)b->mass;
    if (p->bx)
        p->bx[j] = (float)b->pos[0], p->by[j] = (float)b->pos[1], p->bz[j] = (float)b->pos[2];
    if (p->stuck)
        p->stuck[j] = 0;
    if (p->hits)
        p->hits[j] = 0;
    if (p->tint)
        p->tint[j] = (float)b->tint;
    if (p->angle0)
        p->angle0[j] = (float)b->angle;
    if (p->spin)
        p->spin[j] = (float)b->spin;
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
    if (p->parent_id)
        p->parent_id[j] = parent ? parent->id : UINT32_MAX;
}

/* The rest of the step after the birth, by the emitter's own method: the
 * state stored at birth is stepped over `age` exactly as a particle started
 * alone at tb would be (the same scheme, substeps no longer than the full
 * step's, operators included). Gravity alone is the constant-acceleration
 * closed form, in double. The start state is saved first for the collide
 * pass, which sweeps this partial step like a full one. */
static void advance_newborn(pfx_sim *s, size_t i, uint32_t j, double gs, double tb, double age) {
    const pfx_emitter *em = &s->effect->emitters[i];
    pfx_pool *p = &s->pools[i];
    if (em->deflector_count) {
        p->start_px[j] = p->px[j], p->start_py[j] = p->py[j], p->start_pz[j] = p->pz[j];
        p->start_vx[j] = p->vx[j], p->start_vy[j] = p->vy[j], p->start_vz[j] = p->vz[j];
    }
    if (em->motion) {
        pfx_motion_pool_f one = pfx_step_motion_view(p, j, 1);
        pfx_motion_advance_f(&s->plans[i], &one, tb, age);
    } else {
        float *x[3] = {p->px, p->py, p->pz}, *v[3] = {p->vx, p->vy, p->vz};
        for (int a = 0; a < 3; a++) {
            double acc = em->accel[a] * gs, x0 = x[a][j], u0 = v[a][j];
            x[a][j] = (float)(x0 + u0 * age + 0.5 * acc * age * age);
            v[a][j] = (float)(u0 + acc * age);
        }
    }
}

bool pfx_sim_make_particle(pfx_sim *s, size_t i, double tb, double t1, const pfx_parent *parent) {
    const pfx_emitter *em = &s->effect->emitters[i];
    pfx_emitter_state *st = &s->emitters[i];
    pfx_pool *p = &s->pools[i];
    /* A scheduled birth: the next id and the next draws of the stream. A
     * child: its id and draws from its event's key (spawn.h), so that it
     * is the same child at any sim.rate, whatever order the step's events
     * come in, and the scheduled births' ids and draws never depend on
     * how many children came between them. */
    pfx_rng child_rng, *rng = &st->rng;
    uint64_t k;
    if (parent) {
        k = pfx_child_id(parent);
        pfx_rng_seed(&child_rng, pfx_mix64(parent->key ^ ((uint64_t)parent->child << 32)),
                     0xc41dULL);
        rng = &child_rng;
    } else {
        k = st->scheduled++;
    }
    st->born++;
    double age = t1 - tb;
    if (p->count == p->capacity || age >= em->max_lifetime) {
        st->dropped += p->count == p->capacity && age < em->max_lifetime;
        if (!parent)
            pfx_rng_advance(&st->rng, st->draws_per_birth);
        return false;
    }
    birth_draws b;
    pfx_birth_draw(em, tb, rng, parent ? parent->pos : NULL,
                   parent && parent->has_normal ? parent->normal : NULL, &b);
    if (parent && parent->inherit_velocity)
        for (int a = 0; a < 3; a++)
            b.vel[a] += parent->vel[a];
    if (age >= b.life)
        return false; /* would already be dead: never created */
    uint32_t j = p->count++;
    write_newborn(p, j, &b, k, tb, parent);
    const double v0[3] = {b.vel[0], b.vel[1], b.vel[2]};
    if (age > 0)
        advance_newborn(s, i, j, b.gs, tb, age);
    if (!em->motion && !p->may_run_away) {
        const float x[3] = {p->px[j], p->py[j], p->pz[j]}, v[3] = {p->vx[j], p->vy[j], p->vz[j]};
        const double a[3] = {em->accel[0] * b.gs, em->accel[1] * b.gs, em->accel[2] * b.gs};
        p->may_run_away = pfx_step_may_run_away(x, v, a, b.life);
    }
    if (age > 0) {
        /* The newborn's partial step is swept like a full one. */
        if (em->deflector_count)
            pfx_step_collide(s, i, j, 1, tb, age);
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
void pfx_sim_emit(pfx_sim *s, size_t i, double t1) {
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
            st->scheduled += n;
            continue;
        }
        double tb = pfx_schedule_peek(&st->sched, em);
        if (!(tb <= t1))
            break;
        pfx_schedule_pop(&st->sched, em);
        pfx_sim_make_particle(s, i, tb, t1, NULL);
    }
}

/* Children a full pool cannot keep: counted (their ids and draws are their
 * events' own, so no stream moves). */
static void drop_births(pfx_emitter_state *st, uint64_t n) {
    st->dropped += n;
    st->born += n;
}

void pfx_spawn_process(pfx_sim *s, double t1) {
    const pfx_effect *e = s->effect;
    if (!s->queues)
        return;
    /* Births may queue further events (on_birth, cycles bounded by depth):
     * repeat until every queue is empty; each pass consumes what was queued. */
    for (int pass = 0; pass < 64; pass++) {
        bool any = false;
        for (size_t i = 0; i < e->emitter_count; i++) {
            pfx_spawn_queue *q = &s->queues[i];
            if (!q->count) {
                drop_births(&s->emitters[i], q->overflow);
                q->overflow = 0;
                continue;
            }
            any = true;
            /* Take the queued records; events the births queue for this same
             * emitter land in the queue again for the next pass. */
            uint32_t n = q->count;
            pfx_emitter_state *st = &s->emitters[i];
            for (uint32_t k = 0; k < n; k++) {
                spawn_record r = q->items[k];
                const pfx_pool *p = &s->pools[i];
                for (uint64_t c = 0; c < r.births; c++) {
                    if (p->count == p->capacity) {
                        /* None of the rest can be kept: dropped at once. */
                        drop_births(st, r.births - c);
                        break;
                    }
                    r.parent.child = (uint32_t)c;
                    pfx_sim_make_particle(s, i, r.t, t1, &r.parent);
                }
            }
            /* The births that found the queue at the pool's capacity come
             * after every queued one, as they were raised after them. */
            drop_births(st, q->overflow);
            q->overflow = 0;
            memmove(q->items, q->items + n, (q->count - n) * sizeof *q->items);
            q->count -= n;
        }
        if (!any)
            break;
    }
    /* A new step: what is still queued (events raised after this pass, or
     * past the last pass) counts against the pool again. */
    for (size_t i = 0; i < e->emitter_count; i++) {
        pfx_spawn_queue *q = &s->queues[i];
        q->queued = 0;
        for (uint32_t k = 0; k < q->count; k++)
            q->queued += q->items[k].births;
    }
}
