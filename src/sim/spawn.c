/* Sub-emitter events. Events are queued during a step (births, deaths at
 * their exact time and place on the path, deflector hits with the
 * surface normal, trail births along the path) and turned into particles
 * after every emitter has moved (newborn.c), so the result does not depend
 * on the order of emitters in the file. Queues are allocated once, no
 * larger than their targets' pools; births past what a pool can take in a
 * step are counted as dropped by the target, never silently lost. */
#include "sim/spawn.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sim/sample.h"
#include "sim/step.h"

bool pfx_spawn_has(const pfx_emitter *em, pfx_spawn_event event) {
    for (size_t k = 0; k < em->spawn_count; k++)
        if (em->spawns[k].event == event)
            return true;
    return false;
}

size_t pfx_spawn_queue_capacity(const pfx_effect *e, size_t target) {
    const double dt = 1.0 / e->sim_rate;
    double cap = 0;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        for (size_t k = 0; k < em->spawn_count; k++) {
            const pfx_spawn *sp = &em->spawns[k];
            if (sp->target != target)
                continue;
            double per = sp->event == PFX_SPAWN_HIT     ? PFX_COLLIDE_MAX_HITS
                         : sp->event == PFX_SPAWN_TRAIL ? ceil(sp->rate * dt) + 1
                                                        : 1;
            cap += per * em->capacity;
        }
    }
    if (cap == 0)
        return 0;
    /* Each record holds at least one birth: the pool bounds them. */
    double pool = e->emitters[target].capacity;
    return (size_t)(cap + 16 < pool ? cap + 16 : pool);
}

bool pfx_spawn_queues_create(pfx_sim *s) {
    const pfx_effect *e = s->effect;
    s->queues = calloc(e->emitter_count + 1, sizeof *s->queues);
    if (!s->queues)
        return false;
    for (size_t i = 0; i < e->emitter_count; i++) {
        s->queues[i].cap = (uint32_t)pfx_spawn_queue_capacity(e, i);
        if (!s->queues[i].cap)
            continue;
        s->queues[i].items = malloc(s->queues[i].cap * sizeof *s->queues[i].items);
        if (!s->queues[i].items)
            return false;
    }
    return true;
}

/* The key of sub-emitter k's event number `number` of the particle with
 * id `id` of emitter i (pfx_parent.key). */
static uint64_t event_key(const pfx_sim *s, size_t i, size_t k, uint32_t id, uint64_t number) {
    uint64_t h = pfx_mix64(s->emitters[i].spawn_key ^ (uint64_t)k);
    h = pfx_mix64(h ^ ((uint64_t)id << 1 | 1));
    return pfx_mix64(h ^ number);
}

/* Draws the event's count and probability from a generator seeded by its
 * key (so whether and how often an event fires is the same at any step
 * rate and in any order) and queues it when it fires: the record to fill
 * in, with the key set, or NULL when it did not fire or the target's pool
 * cannot take its births (then they are counted to drop). */
static spawn_record *queue_event(pfx_sim *s, const pfx_spawn *sp, double t, uint64_t key) {
    s->emitters[sp->target].spawn_events++;
    pfx_rng rng;
    pfx_rng_seed(&rng, key, 0x5ba3ULL);
    double count = pfx_sample_value(&sp->count, &rng);
    double u = pfx_rng_unit(&rng);
    if (u >= sp->probability || count < 1)
        return NULL;
    const uint64_t births = (uint64_t)floor(count);
    pfx_spawn_queue *q = &s->queues[sp->target];
    if (q->queued >= s->effect->emitters[sp->target].capacity || q->count == q->cap) {
        q->overflow += births;
        return NULL;
    }
    q->queued += births;
    spawn_record *r = &q->items[q->count++];
    r->t = t;
    r->births = (uint32_t)births;
    r->parent.key = key;
    return r;
}

void pfx_spawn_queues_destroy(pfx_sim *s) {
    if (!s->queues)
        return;
    for (size_t i = 0; i < s->effect->emitter_count; i++)
        free(s->queues[i].items);
    free(s->queues);
    s->queues = NULL;
}

void pfx_spawn_capture(const pfx_sim *s, size_t i, pfx_spawn_event event, uint32_t j, double t,
                       const double pos[3], const double vel[3], const double normal[3],
                       pfx_spawn_source *src) {
    const pfx_emitter *em = &s->effect->emitters[i];
    const pfx_pool *p = &s->pools[i];
    src->t = t;
    memcpy(src->pos, pos, sizeof src->pos);
    memcpy(src->vel, vel, sizeof src->vel);
    src->has_normal = normal != NULL;
    if (normal)
        memcpy(src->normal, normal, sizeof src->normal);
    src->generation = p->generation ? p->generation[j] : 0;
    /* a hit's number: the impacts before it (collide_resolve.c raises the
     * count after on_hit) */
    src->number = event == PFX_SPAWN_HIT && p->hits ? p->hits[j] : 0;
    src->id = p->id[j];
    bool color = false, size = false;
    for (size_t k = 0; k < em->spawn_count; k++)
        if (em->spawns[k].event == event)
            color |= em->spawns[k].inherit_color, size |= em->spawns[k].inherit_size;
    if (color) {
        float c[4];
        pfx_particle_color(em, p, j, c);
        src->color[0] = c[0], src->color[1] = c[1], src->color[2] = c[2];
    }
    src->size = size ? pfx_particle_size(em, p, j) : 1;
}

void pfx_spawn_queue_source(pfx_sim *s, size_t i, pfx_spawn_event event,
                            const pfx_spawn_source *src) {
    const pfx_emitter *em = &s->effect->emitters[i];
    for (size_t k = 0; k < em->spawn_count; k++) {
        const pfx_spawn *sp = &em->spawns[k];
        if (sp->event != event || (sp->depth && src->generation >= (float)sp->depth))
            continue;
        spawn_record *r = queue_event(s, sp, src->t, event_key(s, i, k, src->id, src->number));
        if (!r)
            continue;
        pfx_parent *pa = &r->parent;
        memcpy(pa->pos, src->pos, sizeof pa->pos);
        memcpy(pa->vel, src->vel, sizeof pa->vel);
        pa->has_normal = src->has_normal;
        if (src->has_normal)
            memcpy(pa->normal, src->normal, sizeof pa->normal);
        pa->inherit_velocity = sp->inherit_velocity;
        pa->inherit_color = sp->inherit_color;
        pa->inherit_size = sp->inherit_size;
        pa->generation = src->generation;
        pa->id = src->id;
        if (sp->inherit_color)
            memcpy(pa->color, src->color, sizeof pa->color);
        pa->size = sp->inherit_size ? src->size : 1;
    }
}

void pfx_spawn_event_of(pfx_sim *s, size_t i, pfx_spawn_event event, uint32_t j, double t,
                        const double pos[3], const double vel[3], const double normal[3]) {
    pfx_spawn_source src;
    pfx_spawn_capture(s, i, event, j, t, pos, vel, normal, &src);
    pfx_spawn_queue_source(s, i, event, &src);
}

void pfx_spawn_trails(pfx_sim *s, size_t i, uint32_t first, uint32_t n, double t0, double t1) {
    const pfx_emitter *em = &s->effect->emitters[i];
    const pfx_pool *p = &s->pools[i];
    for (size_t k = 0; k < em->spawn_count; k++) {
        const pfx_spawn *sp = &em->spawns[k];
        if (sp->event != PFX_SPAWN_TRAIL)
            continue;
        for (uint32_t j = first; j < first + n; j++) {
            float generation = p->generation ? p->generation[j] : 0;
            if (sp->depth && generation >= (float)sp->depth)
                continue;
            /* Trail births at the particle's ages m / rate, m = 1, 2, ...,
             * younger than its lifetime: those with age in (a0, a1] happened
             * in this step, where its path was then (pfx_step_state_before).
             * a0 and a1 are t0 - birth and t1 - birth, the very numbers the
             * previous and the next step compute, so each trail time falls
             * in exactly one step whatever the step rate. */
            const double a0 = t0 > p->birth[j] ? t0 - p->birth[j] : 0, a1 = t1 - p->birth[j];
            const double life = p->lifetime[j];
            for (double m = floor(a0 * sp->rate) + 1; m <= floor(a1 * sp->rate); m++) {
                const double at = m / sp->rate;
                if (!(at < life))
                    break;
                const double back = a1 - at;
                const uint64_t key = event_key(s, i, k, p->id[j], (uint64_t)m);
                spawn_record *r = queue_event(s, sp, t1 - back, key);
                if (!r)
                    continue;
                r->parent = (pfx_parent){.inherit_velocity = sp->inherit_velocity,
                                         .inherit_color = sp->inherit_color,
                                         .inherit_size = sp->inherit_size,
                                         .size = 1,
                                         .generation = generation,
                                         .id = p->id[j],
                                         .key = key};
                double pos[3], vel[3];
                pfx_step_state_before(s, i, j, t1, back, pos, vel);
                memcpy(r->parent.pos, pos, sizeof pos);
                memcpy(r->parent.vel, vel, sizeof vel);
                if (sp->inherit_color) {
                    float c[4];
                    pfx_particle_color(em, p, j, c);
                    memcpy(r->parent.color, c, 3 * sizeof(float));
                }
                if (sp->inherit_size)
                    r->parent.size = pfx_particle_size(em, p, j);
            }
        }
    }
}
