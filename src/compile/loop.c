/* `loop: true`: a seamless loop of period `duration`. */
#include <math.h>
#include <string.h>

#include "compile/compiler.h"

/* What stops emitter i's sub-emitters from repeating every period, said
 * at the spawn: a random count or chance is drawn from a stream that runs
 * on across periods, so the number of children differs from loop to loop;
 * a fixed, certain count makes the same number, but the children draw
 * their random values from their emitter's stream, which starts over only
 * at a period's first birth of its own (sim/newborn.c), not in step with
 * the events: the loop is exact only by luck, or when the child emitter
 * draws nothing at random (compile cannot tell: what a birth draws is the
 * simulation's business), hence "may". */
static void warn_spawns(compiler *c, const pfx_node *emitters, size_t i) {
    const pfx_emitter *em = &c->e->emitters[i];
    const pfx_node *n = emitters->pairs[i].value;
    for (size_t k = 0; k < em->spawn_count; k++) {
        const pfx_spawn *sp = &em->spawns[k];
        const char *event = pfx_kind_name(pfx_spawn_event_names, (int)sp->event);
        const char *target = c->e->emitters[sp->target].name;
        /* The spawn's own node: the k-th of its event's, in file order. */
        const pfx_node *v = pfx_node_get(n, event), *at = v;
        size_t nth = 0;
        for (size_t j = 0; j < k; j++)
            nth += em->spawns[j].event == sp->event;
        if (v && v->kind == PFX_NODE_SEQ)
            at = nth < v->count ? v->items[nth] : v;
        if (!at)
            at = emitters->pairs[i].key;
        const pfx_node *count = pfx_node_get(at, "count"),
                       *chance = pfx_node_get(at, "probability");
        if (sp->count.dist != PFX_DIST_CONST)
            pfx_read_warning(&c->r, count ? count : at, PFX_RULE_LOOP_SEAM,
                             "the %s sub-emitter of '%s' draws a random count per event, which "
                             "does not repeat every period: the loop is not exact",
                             event, em->name);
        else if (sp->probability < 1)
            pfx_read_warning(&c->r, chance ? chance : at, PFX_RULE_LOOP_SEAM,
                             "the %s sub-emitter of '%s' fires by chance (probability %g), "
                             "which does not repeat every period: the loop is not exact",
                             event, em->name, sp->probability);
        else
            pfx_read_warning(&c->r, at, PFX_RULE_LOOP_SEAM,
                             "the %s sub-emitter of '%s' makes the same count each period, but "
                             "the random values of the particles of '%s' it makes need not "
                             "repeat every period, so the loop may not be exact",
                             event, em->name, target);
    }
}

/* A seamless loop of period P = duration: every emitter's schedule repeats
 * with period P (or a divisor it states) and draws the same values each
 * period; keyframes repeat too. Frames come from one period starting once
 * every particle alive belongs to the periodic regime (after the longest
 * start + lifetime chain), so frame N = duration x fps is frame 0. What
 * cannot repeat is a warning at the place that says it. */
void pfx_compile_loop(compiler *c, const pfx_node *root, const pfx_node *loop,
                      const pfx_node *emitters) {
    pfx_effect *e = c->e;
    const double period = e->duration;
    double frames = period * e->fps;
    if (fabs(frames - round(frames)) > 1e-9 * frames) {
        pfx_read_error(&c->r, loop, PFX_RULE_INCONSISTENT_VALUES,
                       "a looping effect needs duration x fps to be whole frames, got %g", frames);
        return;
    }
    e->loop_frames = lround(frames);
    double settle = 0;
    for (size_t i = 0; i < e->emitter_count; i++) {
        pfx_emitter *em = &e->emitters[i];
        const pfx_node *n = emitters->pairs[i].value, *v;
        settle += em->max_lifetime; /* a chain of sub-emitters at worst */
        if (em->start > settle)
            settle = em->start + em->max_lifetime;
        em->key_period = period;
        if (!em->loop) {
            em->loop = true;
            em->duration = period;
        } else if (fabs(period / em->duration - round(period / em->duration)) > 1e-9) {
            pfx_read_warning(&c->r, pfx_node_get(n, "duration"), PFX_RULE_LOOP_SEAM,
                             "emitter '%s' repeats every %g s, which does not divide the loop's "
                             "%g s: the loop will show a seam",
                             em->name, em->duration, period);
        }
        const char *keys[] = {"position", "rotation"};
        const pfx_keys3 *kf[] = {&em->position_keys, &em->rotation_keys};
        for (int k = 0; k < 2; k++)
            if (kf[k]->count > 1 &&
                memcmp(kf[k]->v[0], kf[k]->v[kf[k]->count - 1], sizeof(double[3])))
                pfx_read_warning(&c->r, pfx_node_get(n, keys[k]), PFX_RULE_LOOP_SEAM,
                                 "'%s' keyframes end elsewhere than they start: the loop will "
                                 "jump at the seam",
                                 keys[k]);
        if (em->rate_kind == PFX_RATE_CURVE &&
            em->rate_curve.v[0] != em->rate_curve.v[em->rate_curve.count - 1])
            pfx_read_warning(&c->r, pfx_node_get(n, "rate"), PFX_RULE_LOOP_SEAM,
                             "the rate curve ends at another value than it starts: the loop will "
                             "change rate at the seam");
        for (size_t b = 0; b < em->burst_count; b++)
            if (em->bursts[b].cycles == 1 && (v = pfx_node_get(n, "bursts")))
                pfx_read_warning(&c->r, v->items[b], PFX_RULE_LOOP_SEAM,
                                 "a one-shot burst repeats every %g s when the effect loops",
                                 period);
        warn_spawns(c, emitters, i);
        for (size_t d = 0; d < em->deflector_count; d++) {
            const pfx_deflector *df = &em->deflectors[d];
            if (df->resilience[0] != df->resilience[1] || df->friction[0] != df->friction[1])
                pfx_read_warning(&c->r, emitters->pairs[i].key, PFX_RULE_LOOP_SEAM,
                                 "deflector '%s' draws a random response per hit: the loop is "
                                 "not exact",
                                 df->name);
        }
    }
    for (size_t f = 0; f < e->force_count; f++)
        if (e->forces[f].spec.kind == PFX_MOTION_TURBULENCE && e->forces[f].spec.speed != 0) {
            const pfx_node *fn = pfx_node_get(pfx_node_get(root, "forces"), e->forces[f].name);
            const pfx_node *at = pfx_node_get(fn, "speed");
            pfx_read_warning(&c->r, at ? at : root, PFX_RULE_LOOP_SEAM,
                             "turbulence '%s' drifts with 'speed': the loop will show a seam",
                             e->forces[f].name);
        }
    e->loop_start = fmax(e->prewarm, ceil(settle / period - 1e-9) * period);
}
