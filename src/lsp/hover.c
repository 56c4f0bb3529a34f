/* Hover: what a key means, from the compiler's key tables (its text with
 * the unit, its form, range and default, from compile/key_doc.c as the
 * schema's descriptions are), then what pfx derives there from the
 * compiled effect: on an emitter's `rate`, the pool it implies; on a
 * drag's `k`, k*dt and the integrators that stay stable. On a
 * force, deflector or emitter name: what it is and who refers to it. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compile/compiler.h"
#include "compile/key_doc.h"
#include "lsp/document.h"
#include "lsp/tree.h"
#include "model/motion.h"

/* A growing markdown text in a fixed buffer (hover texts are short). */
typedef struct text {
    char buf[4096];
    size_t n;
} text;

static void put(text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(text *t, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    int w = vsnprintf(t->buf + t->n, sizeof t->buf - t->n, fmt, ap);
    va_end(ap);
    if (w > 0)
        t->n = t->n + (size_t)w < sizeof t->buf ? t->n + (size_t)w : sizeof t->buf - 1;
}

static void put_names(text *t, const char *const *names) {
    for (size_t i = 0; names[i]; i++)
        put(t, "%s`%s`", i ? ", " : "", names[i]);
}

/* The row's own text (shared with the schema's descriptions) under its name
 * and where it sits. */
static void put_row(text *t, const pfx_key *k, const char *where) {
    char doc[2048];
    pfx_key_doc(k, true, doc, sizeof doc);
    put(t, "**%s** (%s)\n\n%s\n\n", k->name, where, doc);
}

/* The compiled emitter named em, or NULL (the effect did not compile). */
static const pfx_emitter *compiled_emitter(const pfx_lsp_doc *d, const char *em) {
    const pfx_effect *e = d->loaded.effect;
    for (size_t i = 0; e && em && i < e->emitter_count; i++)
        if (!strcmp(e->emitters[i].name, em))
            return &e->emitters[i];
    return NULL;
}

/* On a drag's k: k*dt at the effect's simulation rate, and which
 * integrators keep that decay stable (the model's own limits). */
static void put_drag(text *t, const pfx_lsp_doc *d, const pfx_lsp_hit *h) {
    const pfx_effect *e = d->loaded.effect;
    const pfx_node *v = h->in.map ? pfx_node_get(h->in.map, "k") : NULL;
    char *end;
    double k = v && v->kind == PFX_NODE_SCALAR ? strtod(v->text, &end) : NAN;
    if (!e || !(e->sim_rate > 0) || !isfinite(k) || *end)
        return;
    double z = k / e->sim_rate;
    put(t, "---\n\nk*dt = %.3g at sim.rate %g steps/s. Stable:", z, e->sim_rate);
    int n = 0;
    for (int i = PFX_INTEGRATOR_AUTO + 1; pfx_integrator_names[i]; i++)
        if (z < pfx_stability_decay_limit(pfx_integrator_scheme((pfx_integrator)i)))
            put(t, "%s `%s`", n++ ? "," : "", pfx_integrator_names[i]);
    put(t, "%s. Unstable:", n ? "" : " none");
    n = 0;
    for (int i = PFX_INTEGRATOR_AUTO + 1; pfx_integrator_names[i]; i++)
        if (!(z < pfx_stability_decay_limit(pfx_integrator_scheme((pfx_integrator)i))))
            put(t, "%s `%s`", n++ ? "," : "", pfx_integrator_names[i]);
    put(t, "%s.\n\n", n ? "" : " none");
}

static void put_derived(text *t, const pfx_lsp_doc *d, const pfx_lsp_hit *h) {
    if (h->in.table && h->in.table->kind && h->in.family && !strcmp(h->in.family->name, "force") &&
        !strcmp(h->in.table->kind, "drag") && !strcmp(h->row->name, "k")) {
        put_drag(t, d, h);
        return;
    }
    const pfx_emitter *em = compiled_emitter(d, h->in.emitter);
    if (!em || h->in.table == NULL || strcmp(h->row->name, "rate"))
        return;
    put(t,
        "---\n\nPool of '%s': up to %u live particles (%g births/s at most x max lifetime "
        "%g s, plus bursts and sub-emitters)%s\n\n",
        em->name, (unsigned)em->capacity, pfx_emitter_max_rate(em) + em->spawned_rate,
        em->max_lifetime, em->saturates ? "; cut by the particle budget, it saturates" : "");
}

typedef struct ref_count {
    pfx_lsp_section section;
    const char *name;
    int refs;
} ref_count;

static void count_ref(const pfx_lsp_name *n, void *ctx) {
    ref_count *c = ctx;
    if (!n->definition && n->section == c->section && !strcmp(n->node->text, c->name))
        c->refs++;
}

static const char *const section_words[PFX_LSP_SECTIONS] = {"force", "deflector", "emitter"};

json_t *pfx_lsp_hover(const pfx_lsp_doc *d, int line, int character) {
    const pfx_node *root = d->loaded.doc.root;
    int col = pfx_lsp_col_of_char(&d->lines, line, character);
    line++;
    text t = {{0}, 0};
    const pfx_node *at = NULL;
    pfx_lsp_name nm;
    pfx_lsp_hit h;
    if (pfx_lsp_name_at(root, line, col, &nm)) {
        ref_count c = {nm.section, nm.node->text, 0};
        pfx_lsp_names(root, count_ref, &c);
        put(&t, "**%s** (%s)\n\n%s; %d reference%s in this file\n", nm.node->text,
            section_words[nm.section], nm.definition ? "defined here" : "a reference", c.refs,
            c.refs == 1 ? "" : "s");
        at = nm.node;
    } else if (pfx_lsp_find(root, line, col, &h)) {
        at = h.value ? h.value : h.key;
        if (h.key && !strcmp(h.key->text, "type") && h.in.family) {
            put(&t, "**type** (%s)\n\n%s\n\nOne of ", h.in.family->name, h.in.family->type_doc);
            put_names(&t, h.in.family->kinds);
            put(&t, "\n\n");
            if (h.in.table && h.in.table->doc)
                put(&t, "`%s`: %s\n", h.in.table->kind, h.in.table->doc);
        } else if (h.row) {
            char where[96];
            if (h.in.emitter && h.in.table == &pfx_emitter_table)
                snprintf(where, sizeof where, "emitter '%s'", h.in.emitter);
            else if (h.in.family)
                snprintf(where, sizeof where, "%s%s%s", h.in.family->name, h.in.table ? " " : "",
                         h.in.table ? h.in.table->kind : "");
            else
                snprintf(where, sizeof where, "%s", h.in.table->name);
            put_row(&t, h.row, where);
            put_derived(&t, d, &h);
        }
    }
    if (!t.n || !at)
        return json_null();
    return json_pack("{s:{s:s, s:s}, s:o}", "contents", "kind", "markdown", "value", t.buf, "range",
                     pfx_lsp_range_json(d, at->line, at->col, at->span));
}
