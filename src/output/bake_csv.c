/* Writes the bake CSV of bake_csv.h. Rows within an emitter are sorted by
 * birth id (the pool's order is an artefact of swap-remove), so a bake reads
 * in a stable order; the sort uses a scratch index grown as needed. */
#include "output/bake_csv.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "output/atomic_file.h"

/* Rows are sorted by (id, pool index) pairs: qsort has no context argument
 * in C11, so the key travels with the index. */
typedef struct id_index {
    uint32_t id, index;
} id_index;

struct pfx_bake {
    pfx_atomic_file *file; /* output/atomic_file.h: whole or absent */
    FILE *f;
    bool failed; /* a write failed: its errno is in file */
    id_index *order;
    size_t order_cap;
};

pfx_bake *pfx_bake_open(const char *path, pfx_diags *d) {
    pfx_bake *b = calloc(1, sizeof *b);
    if (!b) {
        pfx_diag_error(d, "cannot write '%s': %s", path, strerror(ENOMEM));
        return NULL;
    }
    if (!(b->file = pfx_atomic_open(path, d))) {
        free(b);
        return NULL;
    }
    b->f = pfx_atomic_stream(b->file);
    if (fputs(PFX_BAKE_HEADER "\n", b->f) < 0) {
        pfx_atomic_failed(b->file, errno);
        b->failed = true;
    }
    return b;
}

/* Records the first failed write with its errno; false from then on. */
static bool write_failed(pfx_bake *b, int errnum) {
    if (!b->failed)
        pfx_atomic_failed(b->file, errnum);
    b->failed = true;
    return false;
}

static int by_id(const void *a, const void *b) {
    uint32_t x = ((const id_index *)a)->id, y = ((const id_index *)b)->id;
    return x < y ? -1 : x > y;
}

bool pfx_bake_frame(pfx_bake *b, const pfx_sim *s, long frame, double time) {
    const pfx_effect *e = s->effect;
    if (b->failed)
        return false;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        const pfx_pool *p = &s->pools[i];
        if (p->count > b->order_cap) {
            id_index *o = realloc(b->order, p->count * sizeof *o);
            if (!o)
                return write_failed(b, ENOMEM);
            b->order = o;
            b->order_cap = p->count;
        }
        for (uint32_t j = 0; j < p->count; j++)
            b->order[j] = (id_index){p->id[j], j};
        if (p->count > 1)
            qsort(b->order, p->count, sizeof *b->order, by_id);
        /* RFC 4180: a name with a comma, quote or line break is quoted. */
        char name[512];
        if (strpbrk(em->name, ",\"\r\n")) {
            size_t o = 0;
            name[o++] = '"';
            for (const char *c = em->name; *c && o < sizeof name - 3; c++) {
                if (*c == '"')
                    name[o++] = '"';
                name[o++] = *c;
            }
            name[o++] = '"';
            name[o] = 0;
        } else {
            snprintf(name, sizeof name, "%s", em->name);
        }
        for (uint32_t k = 0; k < p->count; k++) {
            uint32_t j = b->order[k].index;
            float c[4];
            pfx_particle_color(em, p, j, c);
            int n = fprintf(
                b->f,
                "%ld,%.9g,%s,%u,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
                frame, time, name, p->id[j], p->px[j], p->py[j], p->pz[j], p->vx[j], p->vy[j],
                p->vz[j], pfx_particle_age(p, j), p->lifetime[j], pfx_particle_size(em, p, j), c[0],
                c[1], c[2], c[3]);
            if (n < 0)
                return write_failed(b, errno);
        }
    }
    return !ferror(b->f) || write_failed(b, errno);
}

bool pfx_bake_close(pfx_bake *b, bool commit, pfx_diags *d) {
    bool ok = true;
    /* A failed write is reported (with its path and errno) even when the
     * caller gives up for that reason; any other reason is the caller's. */
    if (commit || b->failed)
        ok = pfx_atomic_commit(b->file, true, d) && commit;
    else
        pfx_atomic_abort(b->file);
    free(b->order);
    free(b);
    return ok || !commit;
}
