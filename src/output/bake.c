/* The particle cache of bake.h: where it goes (an atomic file,
 * output/atomic_file.h, or standard output) and which format writes its
 * rows. The rows come made and ordered (jobs/bake_view.c); the formats
 * themselves are bake_csv.c and bake_ply.c. */
#include "output/bake.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "model/kinds.h"
#include "output/atomic_file.h"
#include "output/bake_rows.h"

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

struct pfx_bake {
    pfx_bake_format format;
    const pfx_effect *effect;
    pfx_atomic_file *file; /* the destination, or NULL for stdout */
    FILE *out;             /* file's stream, or stdout */
    FILE *body;            /* PLY and pcache: the records, until the count is known */
    uint64_t records;      /* written to body */
    int error;             /* the errno of the first failed write, 0 if none */
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

static bool write_row(pfx_bake *b, const pfx_bake_row *row) {
    if (b->format == PFX_BAKE_CSV)
        return pfx_bake_csv_row(b->out, row);
    unsigned char rec[PFX_BAKE_RECORD_BYTES];
    pfx_bake_record(row, rec);
    b->records++;
    return fwrite(rec, sizeof rec, 1, b->body) == 1;
}

bool pfx_bake_rows(pfx_bake *b, const pfx_bake_row *rows, size_t count) {
    if (b->error)
        return false;
    for (size_t k = 0; k < count; k++)
        if (!write_row(b, &rows[k]))
            return write_failed(b, errno);
    return !ferror(b->out) || write_failed(b, errno);
}

bool pfx_bake_fail(pfx_bake *b, int errnum) { return write_failed(b, errnum); }

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
    free(b);
    return ok || !commit;
}
