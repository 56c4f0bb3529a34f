/* Size, colour and alpha over a particle's life. Curves over normalised age
 * are sampled once into 256-entry tables (like gradients), so the per-frame
 * cost is one lookup whatever the number of keys; the two-key {start, end}
 * size stays a per-particle linear rate. */
#include "compile/compile_appearance.h"

#include <string.h>

#define MAX_SIZE 1e6

static bool range_value(pfx_reader *r, const pfx_node *n, const char *what, pfx_value *v, double lo,
                        double hi) {
    return pfx_read_value_in(r, n, what, v, lo, false, hi);
}

/* `[{at: u, value: v}, ...]` with u in [0, 1] increasing, sampled into lut
 * (linear between keys, held beyond the ends). */
bool pfx_read_life_curve(pfx_reader *r, const pfx_node *n, const char *what, double lo, double hi,
                         float lut[PFX_GRADIENT_LUT]) {
    enum { MAX_KEYS = 64 };
    double at[MAX_KEYS], val[MAX_KEYS];
    pfx_key_list_spec spec = {what, "at", MAX_KEYS, 1, false, 0, 1, lo, hi};
    if (!pfx_read_key_list(r, n, &spec, at, val))
        return false;
    for (int i = 0; i < PFX_GRADIENT_LUT; i++) {
        double u = (double)i / (PFX_GRADIENT_LUT - 1);
        size_t k = 0;
        while (k + 1 < n->count && at[k + 1] <= u)
            k++;
        double v = val[k];
        if (k + 1 < n->count && u > at[k])
            v = val[k] + (val[k + 1] - val[k]) * (u - at[k]) / (at[k + 1] - at[k]);
        lut[i] = (float)v;
    }
    return true;
}

static void compile_size(pfx_reader *r, const pfx_node *n, pfx_emitter *em) {
    static const char *const size_keys[] = {"start", "end", NULL};
    if (n->kind == PFX_NODE_SEQ && n->count > 0 && n->items[0]->kind == PFX_NODE_MAP) {
        em->size_curve = pfx_read_life_curve(r, n, "size", 0, MAX_SIZE, em->size_lut);
        return;
    }
    if (n->kind == PFX_NODE_MAP && (pfx_node_get(n, "start") || pfx_node_get(n, "end"))) {
        pfx_read_check_keys(r, n, size_keys, "'size'");
        const pfx_node *s = pfx_node_get(n, "start"), *e = pfx_node_get(n, "end");
        if (s)
            range_value(r, s, "size", &em->size_start, 0, MAX_SIZE);
        em->size_end = em->size_start;
        if (e)
            range_value(r, e, "size", &em->size_end, 0, MAX_SIZE);
        em->size_same = !e;
    } else {
        range_value(r, n, "size", &em->size_start, 0, MAX_SIZE);
        em->size_end = em->size_start;
        em->size_same = true;
    }
}

static void compile_alpha(pfx_reader *r, const pfx_node *n, pfx_emitter *em) {
    static const char *const alpha_keys[] = {"start", "end", NULL};
    if (n->kind == PFX_NODE_SEQ) {
        em->alpha_curve = pfx_read_life_curve(r, n, "alpha", 0, 1, em->alpha_lut);
        return;
    }
    double a0 = 1, a1 = 1;
    if (n->kind == PFX_NODE_MAP) {
        pfx_read_check_keys(r, n, alpha_keys, "'alpha'");
        const pfx_node *s = pfx_node_get(n, "start"), *e = pfx_node_get(n, "end");
        if ((s && !(pfx_read_number(r, s, "alpha", &a0) &&
                    pfx_check_above(r, s, "alpha", a0, 0, false) &&
                    pfx_check_below(r, s, "alpha", a0, 1, false))) ||
            (e && !(pfx_read_number(r, e, "alpha", &a1) &&
                    pfx_check_above(r, e, "alpha", a1, 0, false) &&
                    pfx_check_below(r, e, "alpha", a1, 1, false))))
            return;
    } else if (!(pfx_read_number(r, n, "alpha", &a0) &&
                 pfx_check_above(r, n, "alpha", a0, 0, false) &&
                 pfx_check_below(r, n, "alpha", a0, 1, false))) {
        return;
    } else {
        a1 = a0;
    }
    for (int i = 0; i < PFX_GRADIENT_LUT; i++)
        em->alpha_lut[i] = (float)(a0 + (a1 - a0) * i / (PFX_GRADIENT_LUT - 1));
    em->alpha_curve = true;
}

/* `color`: a colour or gradient over life, `{random: [c1, c2]}` (a fixed
 * random mix per particle) or `{pick: gradient}` (a fixed random point of
 * the gradient per particle). */
static void compile_color(pfx_reader *r, const pfx_node *n, pfx_emitter *em) {
    static const char *const color_keys[] = {"random", "pick", NULL};
    if (n->kind != PFX_NODE_MAP) {
        pfx_read_gradient(r, n, "color", PFX_HDR_MAX, &em->color);
        return;
    }
    if (!pfx_read_check_keys(r, n, color_keys, "'color'"))
        return;
    const pfx_node *rnd = pfx_node_get(n, "random"), *pick = pfx_node_get(n, "pick");
    if ((rnd != NULL) == (pick != NULL)) {
        pfx_read_error(r, n, PFX_RULE_WRONG_TYPE,
                       "'color' as a mapping takes either {random: [c1, c2]} or "
                       "{pick: gradient}");
        return;
    }
    if (pick) {
        if (pfx_read_gradient(r, pick, "color", PFX_HDR_MAX, &em->color))
            em->color_mode = PFX_COLOR_PICK;
        return;
    }
    if (rnd->kind != PFX_NODE_SEQ || rnd->count != 2 ||
        (rnd->items[0]->kind == PFX_NODE_SCALAR && rnd->items[0]->plain)) {
        pfx_read_error(r, rnd, PFX_RULE_WRONG_TYPE, "'random' takes two colours [c1, c2]");
        return;
    }
    if (pfx_read_color(r, rnd->items[0], "color", PFX_HDR_MAX, em->color_a) &&
        pfx_read_color(r, rnd->items[1], "color", PFX_HDR_MAX, em->color_b))
        em->color_mode = PFX_COLOR_RANDOM;
}

/* `angle` (a value, degrees), `spin` (a value in degrees per second, or a
 * curve over life [{at, value}] integrated once into a table, so the angle
 * at any age is one lookup). Held in radians. */
static void compile_rotation(pfx_reader *r, const pfx_node *n, pfx_emitter *em) {
    const pfx_node *v;
    if ((v = pfx_node_get(n, "angle")) &&
        pfx_read_value_in(r, v, "angle", &em->angle, -1e6, false, 1e6))
        em->angle = pfx_value_scaled(em->angle, PFX_DEGREE);
    if ((v = pfx_node_get(n, "spin"))) {
        if (v->kind == PFX_NODE_SEQ && v->count && v->items[0]->kind == PFX_NODE_MAP) {
            enum { MAX_KEYS = 64 };
            double at[MAX_KEYS], val[MAX_KEYS];
            pfx_key_list_spec spec = {"spin", "at", MAX_KEYS, 1, false, 0, 1, -1e6, 1e6};
            if (!pfx_read_key_list(r, v, &spec, at, val))
                return;
            /* Integral of the piecewise-linear spin over u in [0, 1], by the
             * trapezoid rule on the table's own grid (exact for linear
             * pieces whose keys fall on the grid). */
            double sum = 0, prev = val[0];
            for (int i = 0; i < PFX_GRADIENT_LUT; i++) {
                double u = (double)i / (PFX_GRADIENT_LUT - 1);
                size_t k = 0;
                while (k + 1 < v->count && at[k + 1] <= u)
                    k++;
                double s = val[k];
                if (k + 1 < v->count && u > at[k])
                    s = val[k] + (val[k + 1] - val[k]) * (u - at[k]) / (at[k + 1] - at[k]);
                s *= PFX_DEGREE;
                if (i > 0)
                    sum += 0.5 * (s + prev) / (PFX_GRADIENT_LUT - 1);
                prev = s;
                em->spin_turn_lut[i] = (float)sum;
            }
            em->spin_curve = true;
        } else {
            if (pfx_read_value_in(r, v, "spin", &em->spin, -1e6, false, 1e6))
                em->spin = pfx_value_scaled(em->spin, PFX_DEGREE);
        }
    }
}

bool pfx_compile_appearance(pfx_reader *r, const pfx_node *n, pfx_emitter *em) {
    int errors = r->d->errors;
    const pfx_node *v;
    compile_rotation(r, n, em);
    if ((v = pfx_node_get(n, "size")))
        compile_size(r, v, em);
    if ((v = pfx_node_get(n, "color")))
        compile_color(r, v, em);
    if ((v = pfx_node_get(n, "alpha")))
        compile_alpha(r, v, em);
    return r->d->errors == errors;
}
