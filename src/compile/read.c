/* The typed node readers behind pfx_compile. Each reads one kind of value in
 * every form the format allows and reports anything else at the node, with
 * what was expected; none of them knows where in the effect the value sits. */
#include "compile/read.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "compile/colour_text.h"

static void report(pfx_reader *r, pfx_severity sev, const pfx_node *n, pfx_rule rule,
                   const char *fmt, va_list ap) {
    int span = n->kind == PFX_NODE_SCALAR ? n->span : 1;
    pfx_diag_vadd(r->d, sev, n->line, n->col, span, rule, fmt, ap);
}

pfx_diag_at pfx_read_at(pfx_reader *r, const pfx_node *n) {
    return (pfx_diag_at){r->d, n->line, n->col, n->kind == PFX_NODE_SCALAR ? n->span : 1};
}

void pfx_read_error(pfx_reader *r, const pfx_node *n, pfx_rule rule, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    report(r, PFX_SEV_ERROR, n, rule, fmt, ap);
    va_end(ap);
}

void pfx_read_warning(pfx_reader *r, const pfx_node *n, pfx_rule rule, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    report(r, PFX_SEV_WARNING, n, rule, fmt, ap);
    va_end(ap);
}

/* Optimal string alignment distance (Damerau-Levenshtein without repeated
 * edits of one substring): a swapped pair of letters ('fvo') counts as one
 * edit, like a wrong letter. Case-insensitive. */
static size_t edit_distance(const char *a, const char *b) {
    size_t la = strlen(a), lb = strlen(b);
    if (la > 64 || lb > 64)
        return (size_t)-1;
    size_t d[65][65];
    for (size_t i = 0; i <= la; i++)
        d[i][0] = i;
    for (size_t j = 0; j <= lb; j++)
        d[0][j] = j;
    for (size_t i = 1; i <= la; i++) {
        for (size_t j = 1; j <= lb; j++) {
            int ai = tolower((unsigned char)a[i - 1]), bj = tolower((unsigned char)b[j - 1]);
            size_t best = d[i - 1][j - 1] + (ai != bj);
            if (d[i - 1][j] + 1 < best)
                best = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < best)
                best = d[i][j - 1] + 1;
            if (i > 1 && j > 1 && ai == tolower((unsigned char)b[j - 2]) &&
                tolower((unsigned char)a[i - 2]) == bj && d[i - 2][j - 2] + 1 < best)
                best = d[i - 2][j - 2] + 1;
            d[i][j] = best;
        }
    }
    return d[la][lb];
}

const char *pfx_suggest(const char *word, const char *const *allowed) {
    const char *best = NULL;
    size_t best_d = (size_t)-1;
    for (const char *const *k = allowed; *k; k++) {
        size_t d = edit_distance(word, *k);
        if (d < best_d) {
            best_d = d;
            best = *k;
        }
    }
    /* Close enough to be a typo: at most a third of the word, and at least 1
     * edit for short words. */
    size_t len = strlen(word);
    size_t limit = len / 3 > 1 ? len / 3 : 1;
    if (len > 3 && limit < 2)
        limit = 2;
    return best_d <= limit ? best : NULL;
}

/* Names that users of other engines type, with the pfx key that means the
 * same: Unity's Particle System modules (start_lifetime, gravity_modifier,
 * ...) and Godot's ParticleProcessMaterial (lifetime is shared; amount,
 * initial_velocity, ...). A hint is given only where that key is allowed in
 * the mapping at hand. */
typedef struct engine_key {
    const char *name, *engine, *pfx;
} engine_key;

static const engine_key engine_keys[] = {
    {"start_lifetime", "Unity", "lifetime"},
    {"start_speed", "Unity", "speed"},
    {"start_size", "Unity", "size"},
    {"start_color", "Unity", "color"},
    {"start_rotation", "Unity", "rotation"},
    {"gravity_modifier", "Unity", "gravity_scale"},
    {"rate_over_time", "Unity", "rate"},
    {"emission_rate", "Unity", "rate"},
    {"color_over_lifetime", "Unity", "color"},
    {"size_over_lifetime", "Unity", "size"},
    {"start_delay", "Unity", "start"},
    {"looping", "Unity", "loop"},
    {"simulation_speed", "Unity", "sim"},
    {"initial_velocity", "Godot", "speed"},
    {"initial_velocity_min", "Godot", "speed"},
    {"initial_velocity_max", "Godot", "speed"},
    {"scale_amount", "Godot", "size"},
    {"scale_curve", "Godot", "size"},
    {"color_ramp", "Godot", "color"},
    {"emission_shape", "Godot", "shape"},
    {"one_shot", "Godot", "bursts"},
    {"preprocess", "Godot", "prewarm"},
    {"fixed_fps", "Godot", "rate"},
};

static const engine_key *engine_key_find(const char *name, const char *const *allowed) {
    for (size_t i = 0; i < sizeof engine_keys / sizeof *engine_keys; i++) {
        if (strcmp(engine_keys[i].name, name))
            continue;
        for (const char *const *a = allowed; *a; a++)
            if (!strcmp(*a, engine_keys[i].pfx))
                return &engine_keys[i];
    }
    return NULL;
}

bool pfx_read_check_keys(pfx_reader *r, const pfx_node *map, const char *const *allowed,
                         const char *where) {
    bool ok = true;
    for (size_t i = 0; i < map->count; i++) {
        const pfx_node *k = map->pairs[i].key;
        bool known = false;
        for (const char *const *a = allowed; *a && !known; a++)
            known = strlen(*a) == k->len && memcmp(*a, k->text, k->len) == 0;
        if (known)
            continue;
        /* A key may hold an escaped NUL: show every byte (the printer turns
         * control characters into '?'). */
        char shown[256];
        size_t n = k->len < sizeof shown - 1 ? k->len : sizeof shown - 1;
        for (size_t j = 0; j < n; j++)
            shown[j] = k->text[j] ? k->text[j] : '?';
        shown[n] = 0;
        const engine_key *ek = engine_key_find(k->text, allowed);
        /* Past the cap the message is only counted: no suggestion to find. */
        const char *s = ek || r->d->count >= PFX_DIAG_MAX ? NULL : pfx_suggest(k->text, allowed);
        if (ek)
            pfx_read_error(r, k, PFX_RULE_UNKNOWN_KEY,
                           "unknown key '%s' in %s; %s's '%s' is pfx's '%s'", shown, where,
                           ek->engine, ek->name, ek->pfx);
        else if (s)
            pfx_read_error(r, k, PFX_RULE_UNKNOWN_KEY, "unknown key '%s' in %s; did you mean '%s'?",
                           shown, where, s);
        else
            pfx_read_error(r, k, PFX_RULE_UNKNOWN_KEY, "unknown key '%s' in %s", shown, where);
        ok = false;
    }
    return ok;
}

bool pfx_read_map(pfx_reader *r, const pfx_node *n, const char *what) {
    if (n->kind == PFX_NODE_MAP)
        return true;
    pfx_read_error(r, n, PFX_RULE_WRONG_TYPE, "'%s' must be a mapping, got %s", what,
                   pfx_node_kind_name(n));
    return false;
}

/* YAML 1.2 core schema floats, plus integers; anything else is not a number.
 * Non-finite spellings (.nan, .inf) are numbers but rejected. */
static bool parse_number(const char *s, double *out, bool *finite) {
    *finite = true;
    const char *p = s;
    if (*p == '+' || *p == '-')
        p++;
    if (!strcmp(p, ".inf") || !strcmp(p, ".Inf") || !strcmp(p, ".INF") || !strcmp(s, ".nan") ||
        !strcmp(s, ".NaN") || !strcmp(s, ".NAN")) {
        *finite = false;
        return true;
    }
    bool digits = false;
    while (isdigit((unsigned char)*p)) {
        p++;
        digits = true;
    }
    if (*p == '.') {
        p++;
        while (isdigit((unsigned char)*p)) {
            p++;
            digits = true;
        }
    }
    if (!digits)
        return false;
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-')
            p++;
        if (!isdigit((unsigned char)*p))
            return false;
        while (isdigit((unsigned char)*p))
            p++;
    }
    if (*p)
        return false;
    errno = 0;
    double v = strtod(s, NULL);
    if (errno == ERANGE && fabs(v) > 1.0) {
        *finite = false;
        return true;
    }
    *out = errno == ERANGE ? 0.0 : v;
    return true;
}

bool pfx_read_number(pfx_reader *r, const pfx_node *n, const char *what, double *out) {
    if (n->kind != PFX_NODE_SCALAR || !n->plain) {
        pfx_read_error(r, n, PFX_RULE_WRONG_TYPE, "'%s' must be a number, got %s", what,
                       n->kind == PFX_NODE_SCALAR ? "a quoted string" : pfx_node_kind_name(n));
        return false;
    }
    bool finite;
    if (!parse_number(n->text, out, &finite)) {
        pfx_read_error(r, n, PFX_RULE_WRONG_TYPE, "'%s' must be a number, got '%s'", what, n->text);
        return false;
    }
    if (!finite) {
        pfx_read_error(r, n, PFX_RULE_OUT_OF_RANGE, "'%s' must be a finite number, got '%s'", what,
                       n->text);
        return false;
    }
    return true;
}

bool pfx_read_uint(pfx_reader *r, const pfx_node *n, const char *what, uint64_t *out) {
    if (n->kind == PFX_NODE_SCALAR && n->plain) {
        const char *p = n->text;
        uint64_t v = 0;
        bool ok = *p != 0;
        for (; *p && ok; p++) {
            uint64_t digit = (uint64_t)(*p - '0');
            if (!isdigit((unsigned char)*p) || v > (UINT64_MAX - digit) / 10)
                ok = false;
            else
                v = v * 10 + digit;
        }
        if (ok) {
            *out = v;
            return true;
        }
    }
    pfx_read_error(r, n, PFX_RULE_NOT_INTEGER,
                   "'%s' must be a whole number from 0 to 2^64 - 1, got %s%s%s", what,
                   n->kind == PFX_NODE_SCALAR ? "'" : "",
                   n->kind == PFX_NODE_SCALAR ? n->text : pfx_node_kind_name(n),
                   n->kind == PFX_NODE_SCALAR ? "'" : "");
    return false;
}

bool pfx_read_numbers(pfx_reader *r, const pfx_node *n, const char *what, double *out, int count) {
    if (n->kind != PFX_NODE_SEQ || n->count != (size_t)count) {
        pfx_read_error(r, n, PFX_RULE_WRONG_TYPE, "'%s' must be a list of %d numbers", what, count);
        return false;
    }
    bool ok = true;
    for (int i = 0; i < count; i++)
        ok &= pfx_read_number(r, n->items[i], what, &out[i]);
    return ok;
}

bool pfx_read_string(pfx_reader *r, const pfx_node *n, const char *what, const char **out) {
    if (n->kind != PFX_NODE_SCALAR) {
        pfx_read_error(r, n, PFX_RULE_WRONG_TYPE, "'%s' must be a name, got %s", what,
                       pfx_node_kind_name(n));
        return false;
    }
    if (strlen(n->text) != n->len) {
        pfx_read_error(r, n, PFX_RULE_MALFORMED_VALUE, "'%s' must not contain a NUL character",
                       what);
        return false;
    }
    *out = n->text;
    return true;
}

bool pfx_read_path(pfx_reader *r, const pfx_node *n, const char *what, const char *effect_path,
                   const char **name, char *path, size_t size) {
    if (!pfx_read_string(r, n, what, name))
        return false;
    size_t dir = 0;
    if ((*name)[0] != '/' && effect_path) {
        const char *slash = strrchr(effect_path, '/');
        dir = slash ? (size_t)(slash - effect_path) + 1 : 0;
    }
    if (dir + strlen(*name) + 1 > size) {
        pfx_read_error(r, n, PFX_RULE_TOO_LARGE, "the path of '%s' is too long", *name);
        return false;
    }
    memcpy(path, effect_path, dir);
    strcpy(path + dir, *name);
    return true;
}

static const char *const value_keys[] = {"mean", "var", "normal", "clamp", NULL};

bool pfx_read_value(pfx_reader *r, const pfx_node *n, const char *what, pfx_value *out) {
    memset(out, 0, sizeof *out);
    if (n->kind == PFX_NODE_SCALAR) {
        out->dist = PFX_DIST_CONST;
        return pfx_read_number(r, n, what, &out->a);
    }
    if (n->kind == PFX_NODE_SEQ) {
        double mm[2];
        if (n->count != 2) {
            pfx_read_error(r, n, PFX_RULE_WRONG_TYPE, "'%s' as a list must be [min, max]", what);
            return false;
        }
        if (!pfx_read_numbers(r, n, what, mm, 2))
            return false;
        if (mm[0] > mm[1]) {
            pfx_read_error(r, n, PFX_RULE_INVERTED_RANGE, "'%s' range [%g, %g] has min above max",
                           what, mm[0], mm[1]);
            return false;
        }
        *out = (pfx_value){PFX_DIST_UNIFORM, mm[0], mm[1], 0, 0, PFX_FORM_RANGE};
        return true;
    }
    char where[128];
    snprintf(where, sizeof where, "'%s'", what);
    if (!pfx_read_check_keys(r, n, value_keys, where))
        return false;
    const pfx_node *mean = pfx_node_get(n, "mean"), *var = pfx_node_get(n, "var");
    const pfx_node *normal = pfx_node_get(n, "normal"), *clamp = pfx_node_get(n, "clamp");
    if (mean && !normal && !clamp) {
        double m, v = 0;
        if (!pfx_read_number(r, mean, what, &m) || (var && !pfx_read_number(r, var, what, &v)))
            return false;
        if (v < 0) {
            pfx_read_error(r, var, PFX_RULE_OUT_OF_RANGE,
                           "'var' of '%s' must be at least 0, got %g", what, v);
            return false;
        }
        *out = (pfx_value){PFX_DIST_UNIFORM, m - v, m + v, 0, 0, PFX_FORM_MEAN_VAR};
        return true;
    }
    if (normal && !mean && !var) {
        double ms[2], lohi[2];
        if (!pfx_read_numbers(r, normal, what, ms, 2))
            return false;
        if (ms[1] < 0) {
            pfx_read_error(r, normal, PFX_RULE_OUT_OF_RANGE,
                           "standard deviation of '%s' must be at least 0, got %g", what, ms[1]);
            return false;
        }
        /* Without a clamp the tails are cut at three standard deviations, so
         * every value has finite bounds for pool sizing. */
        lohi[0] = ms[0] - 3 * ms[1];
        lohi[1] = ms[0] + 3 * ms[1];
        if (clamp && !pfx_read_numbers(r, clamp, what, lohi, 2))
            return false;
        if (lohi[0] > lohi[1]) {
            pfx_read_error(r, clamp, PFX_RULE_INVERTED_RANGE, "'clamp' of '%s' has min above max",
                           what);
            return false;
        }
        *out =
            (pfx_value){PFX_DIST_NORMAL, ms[0],   ms[1],
                        lohi[0],         lohi[1], clamp ? PFX_FORM_NORMAL : PFX_FORM_NORMAL_CUT3};
        return true;
    }
    pfx_read_error(r, n, PFX_RULE_WRONG_TYPE,
                   "'%s' must be a number, [min, max], {mean: m, var: v} or "
                   "{normal: [mean, sd], clamp: [lo, hi]}",
                   what);
    return false;
}

/* A list of scalars, quoted or not: an [r, g, b(, a)] colour whose
 * components are then each read as numbers (a quoted one is reported). */
static bool is_scalar_list(const pfx_node *n) {
    if (n->kind != PFX_NODE_SEQ || n->count == 0)
        return false;
    for (size_t i = 0; i < n->count; i++)
        if (n->items[i]->kind != PFX_NODE_SCALAR)
            return false;
    return true;
}

/* One colour written as components: a list of scalars, at least one of
 * them a plain word that starts like a number ([r, g, b], [r, g, b, a], or
 * a malformed [r, g]); a list of quoted "#hex" strings or of words
 * ([red, orange, yellow], a misspelt name among them) is a gradient. */
static bool is_rgb_list(const pfx_node *n) {
    if (!is_scalar_list(n))
        return false;
    for (size_t i = 0; i < n->count; i++) {
        const pfx_node *c = n->items[i];
        if (c->plain && c->len && (isdigit((unsigned char)c->text[0]) || strchr("+-.", c->text[0])))
            return true;
    }
    return false;
}

#define COLOUR_FORMS                                                                               \
    "a colour is \"#rgb\", \"#rgba\", \"#rrggbb\" or \"#rrggbbaa\" (quoted), [r, g, b] or "        \
    "[r, g, b, a] in 0..1, a CSS colour name (red, rebeccapurple) or transparent"

/* An empty plain scalar followed on its line by '#': the user wrote an
 * unquoted hex colour, which YAML read as a comment. Reports that, at the
 * '#', with the quoted form, and returns true; false when it is not so. */
static bool comment_after(pfx_reader *r, const pfx_node *n, const char *what) {
    const char *src = r->d->source, *end = src + r->d->source_len;
    if (!src || n->line < 1)
        return false;
    const char *p = src;
    for (int l = 1; l < n->line && p; l++) {
        p = memchr(p, '\n', (size_t)(end - p));
        p = p ? p + 1 : NULL;
    }
    if (!p)
        return false;
    const char *eol = memchr(p, '\n', (size_t)(end - p));
    eol = eol ? eol : end;
    const char *hash = memchr(p, '#', (size_t)(eol - p));
    if (!hash)
        return false;
    /* libyaml counts columns in characters. */
    int col = 1;
    for (const char *c = p; c < hash; c++)
        col += ((unsigned char)*c & 0xc0) != 0x80;
    if (col < n->col)
        return false;
    int len = 1;
    while (hash + len < eol && !isspace((unsigned char)hash[len]))
        len++;
    pfx_diag_add(r->d, PFX_SEV_ERROR, n->line, col, len, PFX_RULE_MALFORMED_VALUE,
                 "'#' starts a YAML comment, so '%s' is empty; quote the colour: %s: \"%.*s\"",
                 what, what, len, hash);
    pfx_diag_note(r->d, n->line, col, len, COLOUR_FORMS);
    return true;
}

bool pfx_read_color(pfx_reader *r, const pfx_node *n, const char *what, double rgb_max,
                    float out[4]) {
    if (n->kind == PFX_NODE_SCALAR) {
        if (pfx_colour_parse_word(n->text, out))
            return true;
        if (n->plain && n->len == 0 && comment_after(r, n, what))
            return false;
        const char *near = n->text[0] != '#' ? pfx_suggest(n->text, pfx_css_colour_names) : NULL;
        if (near)
            pfx_read_error(r, n, PFX_RULE_MALFORMED_VALUE,
                           "unknown colour '%s' in '%s'; did you mean '%s'?", n->text, what, near);
        else
            pfx_read_error(r, n, PFX_RULE_MALFORMED_VALUE, "malformed colour '%s' in '%s'", n->text,
                           what);
        pfx_diag_note(r->d, n->line, n->col, 1, COLOUR_FORMS);
        return false;
    }
    if (is_scalar_list(n) && (n->count == 3 || n->count == 4)) {
        double c[4] = {0, 0, 0, 1};
        bool ok = true;
        for (size_t i = 0; i < n->count; i++) {
            ok &= pfx_read_number(r, n->items[i], what, &c[i]);
            double hi = i == 3 ? 1 : rgb_max; /* HDR colour, never alpha */
            if (ok && (c[i] < 0 || c[i] > hi)) {
                pfx_read_error(r, n->items[i], PFX_RULE_OUT_OF_RANGE,
                               "%s of '%s' must be in 0..%g, got %g",
                               i == 3 ? "the alpha" : "colour components", what, hi, c[i]);
                ok = false;
            }
        }
        for (int i = 0; i < 4; i++)
            out[i] = (float)c[i];
        return ok;
    }
    pfx_read_error(r, n, PFX_RULE_MALFORMED_VALUE, "malformed colour in '%s'", what);
    pfx_diag_note(r->d, n->line, n->col, 1, COLOUR_FORMS);
    return false;
}

/* Samples the piecewise-linear gradient through `count` stops (at[k],
 * colors[k]) once into out's lookup table: entry i is the colour at age
 * fraction i / (LUT - 1). Before the first stop and after the last, the end
 * colours hold. */
static void fill_gradient_lut(const double *at, const float (*colors)[4], size_t count,
                              pfx_gradient *out) {
    out->constant = true;
    for (int i = 0; i < PFX_GRADIENT_LUT; i++) {
        double t = (double)i / (PFX_GRADIENT_LUT - 1);
        size_t k = 0;
        while (k + 1 < count && at[k + 1] <= t)
            k++;
        for (int c = 0; c < 4; c++) {
            double v;
            if (k + 1 >= count || t <= at[k]) {
                v = colors[k][c];
            } else {
                double u = (t - at[k]) / (at[k + 1] - at[k]);
                v = colors[k][c] + (colors[k + 1][c] - colors[k][c]) * u;
            }
            out->lut[i][c] = (float)v;
            if (out->lut[i][c] != out->lut[0][c])
                out->constant = false;
        }
    }
}

static const char *const stop_keys[] = {"at", "color", NULL};

bool pfx_read_gradient(pfx_reader *r, const pfx_node *n, const char *what, double rgb_max,
                       pfx_gradient *out) {
    enum { MAX_STOPS = 64 };
    float colors[MAX_STOPS][4];
    double at[MAX_STOPS];
    size_t count = 0;
    bool ok = true;
    if (n->kind == PFX_NODE_SCALAR || is_rgb_list(n)) {
        ok = pfx_read_color(r, n, what, rgb_max, colors[0]);
        at[0] = 0;
        count = 1;
    } else if (n->kind == PFX_NODE_SEQ) {
        if (n->count == 0) {
            pfx_read_error(r, n, PFX_RULE_MALFORMED_VALUE,
                           "gradient '%s' needs at least one colour", what);
            return false;
        }
        if (n->count > MAX_STOPS) {
            pfx_read_error(r, n, PFX_RULE_TOO_MANY, "gradient '%s' has %zu stops; the most is %d",
                           what, n->count, MAX_STOPS);
            return false;
        }
        bool stops = n->items[0]->kind == PFX_NODE_MAP;
        for (size_t i = 0; i < n->count; i++) {
            const pfx_node *item = n->items[i];
            if (stops != (item->kind == PFX_NODE_MAP)) {
                pfx_read_error(r, item, PFX_RULE_MALFORMED_VALUE,
                               "a gradient cannot mix plain colours and {at: t, color: c} stops");
                ok = false;
                continue;
            }
            if (!stops) {
                ok &= pfx_read_color(r, item, what, rgb_max, colors[i]);
                at[i] = n->count == 1 ? 0.0 : (double)i / (double)(n->count - 1);
                continue;
            }
            ok &= pfx_read_check_keys(r, item, stop_keys, "a gradient stop");
            const pfx_node *t = pfx_node_get(item, "at"), *c = pfx_node_get(item, "color");
            if (!t || !c) {
                pfx_read_error(r, item, PFX_RULE_MISSING_KEY,
                               "a gradient stop needs both 'at' and 'color'");
                ok = false;
                continue;
            }
            if (!pfx_read_number(r, t, "at", &at[i]) ||
                !pfx_read_color(r, c, what, rgb_max, colors[i])) {
                ok = false;
                continue;
            }
            if (at[i] < 0 || at[i] > 1) {
                pfx_read_error(r, t, PFX_RULE_OUT_OF_RANGE, "'at' must be in 0..1, got %g", at[i]);
                ok = false;
            } else if (i > 0 && at[i] < at[i - 1]) {
                pfx_read_error(r, t, PFX_RULE_OUT_OF_ORDER,
                               "gradient stops must be in increasing 'at' order");
                ok = false;
            }
        }
        count = n->count;
    } else {
        pfx_read_error(r, n, PFX_RULE_WRONG_TYPE, "'%s' must be a colour or a list of colours",
                       what);
        return false;
    }
    if (!ok)
        return false;
    fill_gradient_lut(at, colors, count, out);
    return true;
}

bool pfx_check_above(pfx_reader *r, const pfx_node *n, const char *what, double got, double bound,
                     bool strict) {
    if (strict ? got > bound : got >= bound)
        return true;
    pfx_read_error(r, n, PFX_RULE_OUT_OF_RANGE, "'%s' must be %s %g, got %g", what,
                   strict ? "greater than" : "at least", bound, got);
    return false;
}

bool pfx_check_below(pfx_reader *r, const pfx_node *n, const char *what, double got, double bound,
                     bool strict) {
    if (strict ? got < bound : got <= bound)
        return true;
    pfx_read_error(r, n, PFX_RULE_OUT_OF_RANGE, "'%s' must be %s %g, got %g", what,
                   strict ? "less than" : "at most", bound, got);
    return false;
}

/* Picks `word` from `names` or reports it with a suggestion. */
int pfx_read_enum(pfx_reader *r, const pfx_node *n, const char *key, const char *what,
                  const char *const *names) {
    const char *s;
    if (!pfx_read_string(r, n, key, &s))
        return -1;
    for (int i = 0; names[i]; i++)
        if (!strcmp(names[i], s))
            return i;
    const char *sug = pfx_suggest(s, names);
    char list[256] = "";
    for (int i = 0; names[i]; i++) {
        strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
        strncat(list, names[i], sizeof list - strlen(list) - 1);
    }
    if (sug)
        pfx_read_error(r, n, PFX_RULE_UNKNOWN_CHOICE, "unknown %s '%s'; did you mean '%s'?", what,
                       s, sug);
    else
        pfx_read_error(r, n, PFX_RULE_UNKNOWN_CHOICE, "unknown %s '%s'; expected one of: %s", what,
                       s, list);
    return -1;
}

/* Names the bound of a value the user did not write: "mean - var", or the
 * three-sigma cut of a normal without clamp (with the fix). */
static bool value_bound_error(pfx_reader *r, const pfx_node *n, const char *what,
                              const pfx_value *v, bool low, double got, const char *rule) {
    if (v->form == PFX_FORM_MEAN_VAR)
        pfx_read_error(r, n, PFX_RULE_OUT_OF_RANGE, "'%s' must be %s, but mean %s var is %g", what,
                       rule, low ? "-" : "+", got);
    else if (v->form == PFX_FORM_NORMAL_CUT3)
        pfx_read_error(r, n, PFX_RULE_OUT_OF_RANGE,
                       "'%s' must be %s, but mean %s 3 sd is %g; add a 'clamp'", what, rule,
                       low ? "-" : "+", got);
    else
        pfx_read_error(r, n, PFX_RULE_OUT_OF_RANGE, "'%s' must be %s, got %g", what, rule, got);
    return false;
}

bool pfx_read_value_in(pfx_reader *r, const pfx_node *n, const char *what, pfx_value *v, double lo,
                       bool lo_strict, double hi) {
    if (!pfx_read_value(r, n, what, v))
        return false;
    double min = pfx_value_min(v), max = pfx_value_max(v);
    char rule[64];
    if (lo_strict ? !(min > lo) : !(min >= lo)) {
        snprintf(rule, sizeof rule, "%s %g", lo_strict ? "greater than" : "at least", lo);
        return value_bound_error(r, n, what, v, true, min, rule);
    }
    if (!(max <= hi)) {
        snprintf(rule, sizeof rule, "at most %g", hi);
        return value_bound_error(r, n, what, v, false, max, rule);
    }
    return true;
}

bool pfx_read_vec3_within(pfx_reader *r, const pfx_node *map, const char *key, double out[3],
                          double limit) {
    const pfx_node *n = pfx_node_get(map, key);
    if (!n)
        return true;
    double v[3];
    if (!pfx_read_numbers(r, n, key, v, 3))
        return false;
    for (int i = 0; i < 3; i++)
        if (fabs(v[i]) > limit) {
            pfx_read_error(r, n->items[i], PFX_RULE_OUT_OF_RANGE,
                           "'%s' components must be within +-%g, got %g", key, limit, v[i]);
            return false;
        }
    memcpy(out, v, sizeof v);
    return true;
}

bool pfx_read_key_list(pfx_reader *r, const pfx_node *n, const pfx_key_list_spec *spec, double *t,
                       double *v) {
    const char *const key_names[] = {spec->time_key, "value", NULL};
    if (n->kind != PFX_NODE_SEQ || n->count == 0 || n->count > spec->max) {
        pfx_read_error(
            r, n,
            n->kind != PFX_NODE_SEQ || n->count == 0 ? PFX_RULE_WRONG_TYPE : PFX_RULE_TOO_MANY,
            "'%s' needs 1 to %zu keys {%s, value}", spec->what, spec->max, spec->time_key);
        return false;
    }
    bool ok = true;
    for (size_t i = 0; i < n->count; i++) {
        const pfx_node *k = n->items[i];
        if (!pfx_read_map(r, k, spec->what)) {
            ok = false;
            continue;
        }
        ok &= pfx_read_check_keys(r, k, key_names, "a key");
        const pfx_node *tn = pfx_node_get(k, spec->time_key), *vn = pfx_node_get(k, "value");
        if (!tn || !vn) {
            pfx_read_error(r, k, PFX_RULE_MISSING_KEY, "a key of '%s' needs both '%s' and 'value'",
                           spec->what, spec->time_key);
            ok = false;
            continue;
        }
        double *vi = v + i * (size_t)spec->dims;
        bool read = pfx_read_number(r, tn, spec->time_key, &t[i]) &&
                    (spec->dims == 1 ? pfx_read_number(r, vn, spec->what, vi)
                                     : pfx_read_numbers(r, vn, spec->what, vi, spec->dims));
        if (!read) {
            ok = false;
            continue;
        }
        if (t[i] < spec->t_lo || t[i] > spec->t_hi) {
            pfx_read_error(r, tn, PFX_RULE_OUT_OF_RANGE, "'%s' must be in %g..%g, got %g",
                           spec->time_key, spec->t_lo, spec->t_hi, t[i]);
            ok = false;
        } else if (i > 0 && (spec->strict ? t[i] <= t[i - 1] : t[i] < t[i - 1])) {
            pfx_read_error(r, tn, PFX_RULE_OUT_OF_ORDER,
                           "keys of '%s' must have increasing '%s', got %g after %g", spec->what,
                           spec->time_key, t[i], t[i - 1]);
            ok = false;
        }
        for (int d = 0; d < spec->dims && spec->v_lo < spec->v_hi; d++)
            ok &= pfx_check_above(r, vn, spec->what, vi[d], spec->v_lo, false) &&
                  pfx_check_below(r, vn, spec->what, vi[d], spec->v_hi, false);
    }
    return ok;
}
