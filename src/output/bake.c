/* The particle cache of bake.h: where it goes (an atomic file,
 * output/atomic_file.h, or standard output), the order of its rows (by emitter, then
 * birth id: the pool's order is an artefact of swap-remove), and which
 * format writes them. The formats themselves are bake_csv.c and
 * bake_ply.c. */
#include "output/bake.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "model/kinds.h"
#include "output/atomic_file.h"
#include "output/bake_rows.h"
#include "sim/appearance.h"

static const char *const format_names[] = {
#define PFX_BAKE_NAME(e, name) name,
    PFX_BAKE_FORMATS(PFX_BAKE_NAME)
#undef PFX_BAKE_NAME
        NULL};

const char *pfx_bake_format_name(pfx_bake_format f) {
    return (unsigned)f < PFX_BAKE_FORMAT_COUNT ? format_names[f] : NULL;
}

bool pfx_bake_format_parse(const char *name, pfx_bake_format *out) {
    int f = pfx_kind_find(format_names, name);
    if (f >= 0)
        *out = (pfx_bake_format)f;
    return f >= 0;
}

/* Rows are sorted by (id, pool index) pairs: qsort has no context argument
 * in C11, so the key travels with the index. */
typedef struct id_index {
    uint32_t id, index;
} id_index;

struct pfx_bake {
    pfx_bake_format format;
    const pfx_effect *effect;
    pfx_atomic_file *file; /* the destination, or NULL for stdout */
    FILE *out;             /* file's stream, or stdout */
    FILE *body;            /* PLY and pcache: the records, until the count is known */
    uint64_t records;      /* written to body */
    int error;             /* the errno of the first failed write, 0 if none */
    id_index *order;
    size_t order_cap;
};

/* Records the first failed write with its errno; false from then on. */
static bool write_failed(pfx_bake *b, int errnum) {
    if (!b->error)
        b->error = errnum ? errnum : EIO;
    return false;
}

pfx_bake *pfx_bake_open(const char *path, pfx_bake_format format, const pfx_effect *e,
                        pfx_diags *d) {
    pfx_bake *b = calloc(1, sizeof *b);
    if (!b) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        return NULL;
    }
    b->format = format;
    b->effect = e;
    if (!strcmp(path, "-")) {
        b->out = stdout;
    } else {
        if (!(b->file = pfx_atomic_open(path, d))) {
            free(b);
            return NULL;
        }
        b->out = pfx_atomic_stream(b->file);
    }
    if (format == PFX_BAKE_CSV) {
        if (!pfx_bake_csv_header(b->out))
            write_failed(b, errno);
    } else if (!(b->body = tmpfile())) {
        pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot write '%s': no scratch file: %s", path,
                       strerror(errno));
        pfx_bake_close(b, false, NULL);
        return NULL;
    }
    return b;
}

static int by_id(const void *a, const void *b) {
    uint32_t x = ((const id_index *)a)->id, y = ((const id_index *)b)->id;
    return x < y ? -1 : x > y;
}

static bool write_row(pfx_bake *b, const pfx_bake_row *row) {
    if (b->format == PFX_BAKE_CSV)
        return pfx_bake_csv_row(b->out, row);
    unsigned char rec[PFX_BAKE_RECORD_BYTES];
    pfx_bake_record(row, rec);
    b->records++;
    return fwrite(rec, sizeof rec, 1, b->body) == 1;
}

bool pfx_bake_frame(pfx_bake *b, const pfx_sim *s, long frame, double time) {
    const pfx_effect *e = s->effect;
    if (b->error)
        return false;
    bool ok = true;
    for (size_t i = 0; i < e->emitter_count && ok; i++) {
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
        for (uint32_t k = 0; k < p->count && ok; k++) {
            uint32_t j = b->order[k].index;
            pfx_bake_row row = {.frame = frame,
                                .time = time,
                                .age = pfx_particle_age(p, j),
                                .emitter = (uint32_t)i,
                                .id = p->id[j],
                                .emitter_name = em->name,
                                .pos = {p->px[j], p->py[j], p->pz[j]},
                                .vel = {p->vx[j], p->vy[j], p->vz[j]},
                                .lifetime = p->lifetime[j],
                                .size = pfx_particle_size(em, p, j)};
            pfx_particle_color(em, p, j, row.color);
            ok = write_row(b, &row) || write_failed(b, errno);
        }
    }
    return ok && (!ferror(b->out) || write_failed(b, errno));
}

/* PLY and pcache: the header, then the records copied from the scratch
 * file. */
static bool finish_binary(pfx_bake *b) {
    bool ok = b->format == PFX_BAKE_PLY ? pfx_bake_ply_header(b->out, b->effect, b->records)
                                        : pfx_bake_pcache_header(b->out, b->effect, b->records);
    if (!ok || fflush(b->body) != 0 || fseek(b->body, 0, SEEK_SET) != 0)
        return false;
    char buf[1 << 16];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, b->body)) > 0)
        if (fwrite(buf, 1, n, b->out) != n)
            return false;
    return !ferror(b->body);
}

bool pfx_bake_close(pfx_bake *b, bool commit, pfx_diags *d) {
    if (commit && !b->error && b->body && !finish_binary(b))
        write_failed(b, errno);
    if (b->body)
        fclose(b->body);
    /* A failed write is reported (with its path and errno) even when the
     * caller gives up for that reason; any other reason is the caller's. */
    bool ok = true;
    if (!b->file) {
        if (commit && !b->error && (fflush(stdout) != 0 || ferror(stdout)))
            write_failed(b, errno);
        if (b->error && d)
            pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot write 'standard output': %s",
                           strerror(b->error));
        ok = !b->error;
    } else if (commit || b->error) {
        if (b->error)
            pfx_atomic_failed(b->file, b->error);
        ok = pfx_atomic_commit(b->file, true, d) && !b->error;
    } else {
        pfx_atomic_abort(b->file);
    }
    free(b->order);
    free(b);
    return ok || !commit;
}
