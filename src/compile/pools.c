/* Pool sizes: each emitter's worst case of live particles, within the
 * particle budget. */
#include <math.h>

#include "compile/compiler.h"

/* Its own births' peak plus what sub-emitters can feed it within one
 * lifetime. */
static double pool_need(const pfx_emitter *em) { return pfx_emitter_peak(em) + em->spawned_peak; }

/* Sizes each emitter's pool from its worst case (rate x max lifetime, plus
 * bursts and sub-emitters). When the total exceeds the particle budget, the
 * budget is shared by water-filling: every emitter gets its need or an
 * equal share of what is left, whichever is smaller, smallest needs first,
 * so a small emitter (a firework's shell) is never starved by a huge one
 * (its sparks). Cut emitters saturate, with a warning giving the numbers. */
void pfx_size_pools(compiler *c, const pfx_node *emitters) {
    pfx_effect *e = c->e;
    size_t n = e->emitter_count;
    double need[PFX_MAX_EMITTERS], cap[PFX_MAX_EMITTERS];
    size_t order[PFX_MAX_EMITTERS];
    double need_total = 0;
    for (size_t i = 0; i < n && i < PFX_MAX_EMITTERS; i++) {
        need[i] = pool_need(&e->emitters[i]);
        need_total += need[i];
        order[i] = i;
    }
    /* Insertion sort by need: at most PFX_MAX_EMITTERS emitters, once per compile. */
    for (size_t i = 1; i < n; i++)
        for (size_t k = i; k > 0 && need[order[k]] < need[order[k - 1]]; k--) {
            size_t t = order[k];
            order[k] = order[k - 1];
            order[k - 1] = t;
        }
    double budget = (double)e->max_particles, left = budget;
    for (size_t k = 0; k < n; k++) {
        size_t i = order[k];
        double share = floor(left / (double)(n - k));
        cap[i] = need[i] <= share ? need[i] : share;
        left -= cap[i];
    }
    for (size_t i = 0; i < n; i++) {
        pfx_emitter *em = &e->emitters[i];
        if (need_total > budget && cap[i] < need[i]) {
            em->saturates = true;
            const pfx_node *at = pfx_node_get(emitters->pairs[i].value, "rate");
            if (!at)
                at = emitters->pairs[i].key;
            pfx_read_warning(&c->r, at, PFX_RULE_POOL_SATURATED,
                             "emitter '%s' needs up to %.0f live particles (%g births/s x max "
                             "lifetime %g s, plus bursts and sub-emitters) but gets %.0f of the "
                             "%.0f budget; it will saturate (raise --max-particles or lower "
                             "'rate' or 'lifetime')",
                             em->name, need[i], pfx_emitter_max_rate(em) + em->spawned_rate,
                             em->max_lifetime, cap[i], budget);
        }
        em->capacity = (uint32_t)(cap[i] < 1 ? 1 : cap[i]);
    }
}
