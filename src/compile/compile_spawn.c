/* Sub-emitters. Each spawn names a target emitter; the graph of spawns may
 * contain cycles (fireworks whose sparks burst again) only when every spawn
 * on the cycle has a `depth`, so the number of generations, and with it the
 * pool sizes, stays finite. Worst-case spawned rates are propagated through
 * the graph generation by generation for pool sizing. */
#include "compile/compile_spawn.h"

#include <math.h>
#include <string.h>

#define MAX_SPAWNS 16
#define MAX_DEPTH 16
/* on_hit has no schedule to bound it: pools assume up to this many hits per
 * particle (a saturated child counts its drops; see pfx info). */
#define HITS_PER_PARTICLE 4.0

static const char *const spawn_keys[] = {"emit", "count", "probability", "inherit", "depth", NULL};
static const char *const trail_keys[] = {"emit", "rate", "probability", "inherit", "depth", NULL};
static const char *const inherit_names[] = {"velocity", "color", "size", NULL};

static int find_emitter(const pfx_node *emitters, const char *name, size_t len) {
    for (size_t i = 0; i < emitters->count; i++) {
        const pfx_node *k = emitters->pairs[i].key;
        if (k->len == len && !memcmp(k->text, name, len))
            return (int)i;
    }
    return -1;
}

static bool read_spawn(pfx_reader *r, const pfx_node *n, pfx_spawn_event event,
                       const pfx_node *emitters, pfx_spawn *out) {
    const char *key = event == PFX_SPAWN_TRAIL ? "trail" : "sub-emitter";
    *out = (pfx_spawn){.event = event, .count = pfx_value_const(1), .probability = 1};
    if (!pfx_read_map(r, n, key))
        return false;
    bool ok = pfx_read_check_keys(r, n, event == PFX_SPAWN_TRAIL ? trail_keys : spawn_keys,
                                  event == PFX_SPAWN_TRAIL ? "a trail" : "a sub-emitter");
    const pfx_node *v = pfx_node_get(n, "emit");
    const char *name;
    if (!v) {
        pfx_read_error(r, n, PFX_RULE_MISSING_KEY, "a %s needs 'emit: <emitter name>'", key);
        return false;
    }
    if (!pfx_read_string(r, v, "emit", &name))
        return false;
    int t = find_emitter(emitters, name, v->len);
    if (t < 0) {
        const char *names[257];
        size_t count = emitters->count < 256 ? emitters->count : 256;
        for (size_t i = 0; i < count; i++)
            names[i] = emitters->pairs[i].key->text;
        names[count] = NULL;
        const char *sug = pfx_suggest(name, names);
        if (sug)
            pfx_read_error(r, v, PFX_RULE_UNKNOWN_NAME,
                           "'emit' names no emitter '%s'; did you mean '%s'?", name, sug);
        else
            pfx_read_error(r, v, PFX_RULE_UNKNOWN_NAME, "'emit' names no emitter '%s'", name);
        return false;
    }
    out->target = (uint32_t)t;
    if ((v = pfx_node_get(n, "count")))
        ok &= pfx_read_value_in(r, v, "count", &out->count, 0, false, 1e5);
    if (event == PFX_SPAWN_TRAIL) {
        out->rate = 10;
        if ((v = pfx_node_get(n, "rate")))
            ok &= pfx_read_number(r, v, "rate", &out->rate) &&
                  pfx_check_above(r, v, "rate", out->rate, 0, true) &&
                  pfx_check_below(r, v, "rate", out->rate, 1e4, false);
    }
    if ((v = pfx_node_get(n, "probability")))
        ok &= pfx_read_number(r, v, "probability", &out->probability) &&
              pfx_check_above(r, v, "probability", out->probability, 0, false) &&
              pfx_check_below(r, v, "probability", out->probability, 1, false);
    if ((v = pfx_node_get(n, "depth"))) {
        double d;
        if (pfx_read_number(r, v, "depth", &d) && pfx_check_above(r, v, "depth", d, 1, false) &&
            pfx_check_below(r, v, "depth", d, MAX_DEPTH, false)) {
            if (d != floor(d))
                pfx_read_error(r, v, PFX_RULE_NOT_INTEGER, "'depth' must be a whole number, got %g",
                               d);
            out->depth = (uint32_t)d;
        } else {
            ok = false;
        }
    }
    if ((v = pfx_node_get(n, "inherit"))) {
        if (v->kind != PFX_NODE_SEQ) {
            pfx_read_error(r, v, PFX_RULE_WRONG_TYPE,
                           "'inherit' must be a list of: velocity, color, size");
            return false;
        }
        for (size_t i = 0; i < v->count; i++) {
            int k = pfx_read_enum(r, v->items[i], "inherit", "inherited attribute", inherit_names);
            out->inherit_velocity |= k == 0;
            out->inherit_color |= k == 1;
            out->inherit_size |= k == 2;
            ok &= k >= 0;
        }
    }
    return ok;
}

bool pfx_compile_spawns(pfx_reader *r, const pfx_node *n, const pfx_node *emitters,
                        pfx_emitter *em) {
    static const char *const keys[] = {"on_birth", "on_death", "on_hit", "trail"};
    int errors = r->d->errors;
    pfx_spawn spawns[MAX_SPAWNS];
    size_t count = 0;
    for (int k = 0; k < 4; k++) {
        const pfx_node *v = pfx_node_get(n, keys[k]);
        if (!v)
            continue;
        size_t items = v->kind == PFX_NODE_SEQ ? v->count : 1;
        for (size_t i = 0; i < items; i++) {
            const pfx_node *item = v->kind == PFX_NODE_SEQ ? v->items[i] : v;
            if (count == MAX_SPAWNS) {
                pfx_read_error(r, item, PFX_RULE_TOO_MANY, "an emitter has at most %d sub-emitters",
                               MAX_SPAWNS);
                break;
            }
            if (read_spawn(r, item, (pfx_spawn_event)k, emitters, &spawns[count]))
                count++;
        }
    }
    if (count) {
        em->spawns = pfx_arena_alloc(r->arena, count * sizeof *em->spawns);
        if (em->spawns) {
            memcpy(em->spawns, spawns, count * sizeof *spawns);
            em->spawn_count = count;
        }
    }
    return r->d->errors == errors;
}

/* The node of spawn s of emitter i (for locating cycle errors). */
static const pfx_node *spawn_node(const pfx_node *emitters, size_t i, const pfx_spawn *s) {
    static const char *const keys[] = {"on_birth", "on_death", "on_hit", "trail"};
    const pfx_node *v = pfx_node_get(emitters->pairs[i].value, keys[s->event]);
    return v ? v : emitters->pairs[i].key;
}

/* Depth-first search for a cycle through spawns without depth. */
static bool undepthed_cycle(const pfx_effect *e, size_t from, size_t at, int steps, bool *seen) {
    if (steps > (int)e->emitter_count)
        return false;
    const pfx_emitter *em = &e->emitters[at];
    for (size_t k = 0; k < em->spawn_count; k++) {
        const pfx_spawn *s = &em->spawns[k];
        if (s->depth)
            continue;
        if (s->target == from)
            return true;
        if (!seen[s->target]) {
            seen[s->target] = true;
            if (undepthed_cycle(e, from, s->target, steps + 1, seen))
                return true;
        }
    }
    return false;
}

/* Particles per second a spawn adds to its target for each birth per second
 * of its parent (the worst case of its count). */
static double spawn_factor(const pfx_emitter *parent, const pfx_spawn *s) {
    double per_event = s->probability * floor(pfx_value_max(&s->count));
    switch (s->event) {
    case PFX_SPAWN_TRAIL:
        return s->probability * s->rate * parent->max_lifetime;
    case PFX_SPAWN_HIT:
        return per_event * HITS_PER_PARTICLE;
    default:
        return per_event;
    }
}

/* Reports every emitter whose sub-emitters lead back to it through spawns
 * without a depth (such a cycle would never end), at the spawn that could
 * take one. Returns whether there was none. */
static bool report_cycles(pfx_reader *r, const pfx_effect *e, const pfx_node *emitters) {
    int errors = r->d->errors;
    bool seen[PFX_MAX_EMITTERS];
    for (size_t i = 0; i < e->emitter_count; i++) {
        memset(seen, 0, sizeof seen);
        if (undepthed_cycle(e, i, i, 0, seen)) {
            const pfx_emitter *em = &e->emitters[i];
            const pfx_spawn *s = em->spawn_count ? &em->spawns[0] : NULL;
            for (size_t k = 0; k < em->spawn_count; k++)
                if (!em->spawns[k].depth)
                    s = &em->spawns[k];
            pfx_read_error(r, s ? spawn_node(emitters, i, s) : emitters->pairs[i].key,
                           PFX_RULE_REFERENCE_CYCLE,
                           "sub-emitters of '%s' lead back to it; give 'depth' (generations) "
                           "to bound the cycle",
                           em->name);
        }
    }
    return r->d->errors == errors;
}

/* The columns the spawns' targets need. A depth counts generations along
 * every spawn, so once any spawn has one, every emitter that spawns or is
 * spawned keeps its generation (a cycle with depth on one edge only must
 * still end); a target keeps the parent's colour or size when a spawn
 * passes it on. */
static void mark_kept_columns(pfx_effect *e) {
    size_t n = e->emitter_count;
    bool depths = false;
    for (size_t i = 0; i < n; i++)
        for (size_t k = 0; k < e->emitters[i].spawn_count; k++)
            depths |= e->emitters[i].spawns[k].depth > 0;
    for (size_t i = 0; i < n; i++)
        for (size_t k = 0; k < e->emitters[i].spawn_count; k++) {
            const pfx_spawn *s = &e->emitters[i].spawns[k];
            pfx_emitter *t = &e->emitters[s->target];
            t->keeps_generation |= depths;
            e->emitters[i].keeps_generation |= depths;
            t->keeps_parent_color |= s->inherit_color;
            t->keeps_size_scale |= s->inherit_size;
        }
}

/* One generation g of spawning: adds to next_rate/next_peak[t] the births
 * per second and the most births within one lifetime of t that the spawns
 * still live at g (their depth not reached) feed target t, from their
 * parents' rate and peak of generation g. Returns whether any spawn fed. */
static bool feed_generation(const pfx_effect *e, size_t g, const double *rate, const double *peak,
                            double *next_rate, double *next_peak) {
    bool any = false;
    for (size_t i = 0; i < e->emitter_count; i++) {
        if (!rate[i] && !peak[i])
            continue;
        const pfx_emitter *em = &e->emitters[i];
        for (size_t k = 0; k < em->spawn_count; k++) {
            const pfx_spawn *s = &em->spawns[k];
            if (s->depth && g >= s->depth)
                continue;
            const pfx_emitter *t = &e->emitters[s->target];
            double per_event = s->probability * floor(pfx_value_max(&s->count));
            double events = rate[i] * t->max_lifetime + 1 + peak[i];
            if (s->event == PFX_SPAWN_TRAIL)
                events = peak[i] * (s->rate * t->max_lifetime + 1);
            else if (s->event == PFX_SPAWN_HIT)
                events *= HITS_PER_PARTICLE;
            next_rate[s->target] += spawn_factor(em, s) * rate[i];
            next_peak[s->target] += per_event * events;
            any = true;
        }
    }
    return any;
}

/* Generation by generation, the births per second a spawn feeds its
 * target (factor x the parent's rate) and the most it can feed within one
 * lifetime of the target: events come in bursts (every parent alive may
 * die in one step), so a window of the child's lifetime L holds at most
 * the parent's births in L, plus one, plus every parent alive at its
 * start, each making the largest count. Without depth the graph is
 * acyclic, so n generations reach every emitter; with depth, MAX_DEPTH
 * more bound the cycles. The sums over generations bound each emitter's
 * spawned rate and peak. */
static void bound_spawned(pfx_effect *e) {
    size_t n = e->emitter_count;
    double rate[PFX_MAX_EMITTERS], peak[PFX_MAX_EMITTERS], next_rate[PFX_MAX_EMITTERS],
        next_peak[PFX_MAX_EMITTERS], total_rate[PFX_MAX_EMITTERS], total_peak[PFX_MAX_EMITTERS];
    for (size_t i = 0; i < n; i++) {
        rate[i] = pfx_emitter_max_rate(&e->emitters[i]);
        peak[i] = pfx_emitter_peak(&e->emitters[i]);
        total_rate[i] = total_peak[i] = 0;
    }
    for (size_t g = 0; g < n + MAX_DEPTH; g++) {
        memset(next_rate, 0, n * sizeof *next_rate);
        memset(next_peak, 0, n * sizeof *next_peak);
        bool any = feed_generation(e, g, rate, peak, next_rate, next_peak);
        for (size_t i = 0; i < n; i++) {
            total_rate[i] += next_rate[i];
            total_peak[i] += next_peak[i];
        }
        memcpy(rate, next_rate, n * sizeof *rate);
        memcpy(peak, next_peak, n * sizeof *peak);
        if (!any)
            break;
    }
    for (size_t i = 0; i < n; i++) {
        e->emitters[i].spawned_rate = fmin(total_rate[i], 1e9);
        e->emitters[i].spawned_peak = fmin(ceil(total_peak[i]), 1e9);
    }
}

bool pfx_resolve_spawns(pfx_reader *r, pfx_effect *e, const pfx_node *emitters) {
    if (e->emitter_count > PFX_MAX_EMITTERS) /* pfx_compile checked before compiling them */
        return false;
    if (!report_cycles(r, e, emitters))
        return false;
    mark_kept_columns(e);
    bound_spawned(e);
    return true;
}

/* A ribbon joins the particles one parent's trail laid, so every particle
 * of a ribbon emitter must come from a trail, and all from one emitter's
 * (the parent's id names its strip only within its own emitter). */
bool pfx_check_ribbons(pfx_reader *r, pfx_effect *e, const pfx_node *emitters) {
    static const char *const own[] = {"rate", "interval", "bursts", "lod"};
    int errors = r->d->errors;
    for (size_t t = 0; t < e->emitter_count; t++) {
        pfx_emitter *rib = &e->emitters[t];
        if (rib->look.draw != PFX_DRAW_RIBBON)
            continue;
        const pfx_node *n = emitters->pairs[t].value;
        long feeder = -1;
        bool fed = false; /* by anything, reported or not */
        for (size_t i = 0; i < e->emitter_count; i++)
            for (size_t k = 0; k < e->emitters[i].spawn_count; k++) {
                const pfx_spawn *s = &e->emitters[i].spawns[k];
                if (s->target != t)
                    continue;
                const pfx_node *at = spawn_node(emitters, i, s);
                fed = true;
                if (s->event != PFX_SPAWN_TRAIL)
                    pfx_read_error(r, at, PFX_RULE_INVALID_REFERENCE,
                                   "'%s' cannot feed ribbon emitter '%s': a ribbon's points "
                                   "come from one emitter's 'trail'",
                                   pfx_spawn_event_names[s->event], rib->name);
                else if (i == t)
                    pfx_read_error(r, at, PFX_RULE_REFERENCE_CYCLE,
                                   "ribbon emitter '%s' cannot lay its own trail", rib->name);
                else if (feeder >= 0 && (size_t)feeder != i)
                    pfx_read_error(r, at, PFX_RULE_INVALID_REFERENCE,
                                   "ribbon emitter '%s' is fed by the trails of '%s' and '%s'; "
                                   "give each its own ribbon emitter",
                                   rib->name, e->emitters[feeder].name, e->emitters[i].name);
                else
                    feeder = (long)i;
            }
        if (feeder >= 0)
            rib->ribbon_parent = (uint32_t)feeder;
        else if (!fed)
            pfx_read_error(r, pfx_node_get(n, "draw"), PFX_RULE_INVALID_REFERENCE,
                           "emitter '%s' draws ribbons but no 'trail' emits into it: add "
                           "trail: { emit: %s, rate: R } to the emitter it follows",
                           rib->name, rib->name);
        for (size_t k = 0; k < sizeof own / sizeof *own; k++) {
            const pfx_node *v = pfx_node_get(n, own[k]);
            if (v)
                pfx_read_error(r, v, PFX_RULE_INAPPLICABLE_KEY,
                               "ribbon emitter '%s' gets its points from a trail only; remove "
                               "'%s'",
                               rib->name, own[k]);
        }
    }
    return r->d->errors == errors;
}
