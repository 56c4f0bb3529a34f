/* The Wavefront OBJ reader behind the `mesh` shape: vertices and faces
 * only (texture coordinates, normals, groups and materials are skipped),
 * polygons fan-split into triangles, and the cumulative area table the
 * sampler searches. It reports the first malformed line and stops; it does
 * not sample (src/sim/sample.c does). */
#include "compile/mesh_load.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* A growable array in malloc'd memory, for parsing only: the result is
 * copied into the arena once its size is known. */
typedef struct grow {
    void *p;
    size_t count, cap, elem;
} grow;

static bool grow_push(grow *g, const void *item) {
    if (g->count == g->cap) {
        size_t cap = g->cap ? 2 * g->cap : 1024;
        void *p = realloc(g->p, cap * g->elem);
        if (!p)
            return false;
        g->p = p;
        g->cap = cap;
    }
    memcpy((char *)g->p + g->count * g->elem, item, g->elem);
    g->count++;
    return true;
}

static bool fail(const pfx_diag_at *at, pfx_rule rule, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static bool fail(const pfx_diag_at *at, pfx_rule rule, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    pfx_diag_vadd(at->d, PFX_SEV_ERROR, at->line, at->col, at->span > 0 ? at->span : 1, rule, fmt,
                  ap);
    va_end(ap);
    return false;
}

static bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* The next whitespace-separated token of [*c, end), or false at the end. */
static bool next_token(const char **c, const char *end, const char **tok, size_t *len) {
    const char *p = *c;
    while (p < end && is_space(*p))
        p++;
    if (p == end)
        return false;
    const char *q = p;
    while (q < end && !is_space(*q))
        q++;
    *tok = p;
    *len = (size_t)(q - p);
    *c = q;
    return true;
}

/* A token fit to quote in a message: at most 24 bytes, printable ASCII
 * (the file need not be UTF-8; messages must be). */
static const char *quoted(const char *tok, size_t len, char buf[32]) {
    size_t n = len < 24 ? len : 24, i;
    for (i = 0; i < n; i++)
        buf[i] = tok[i] >= 0x20 && tok[i] < 0x7f ? tok[i] : '?';
    if (len > n)
        buf[i++] = '.', buf[i++] = '.', buf[i++] = '.';
    buf[i] = '\0';
    return buf;
}

static bool parse_double(const char *tok, size_t len, double *out) {
    char buf[64];
    if (len == 0 || len >= sizeof buf)
        return false;
    memcpy(buf, tok, len);
    buf[len] = '\0';
    char *end;
    *out = strtod(buf, &end);
    return end == buf + len && isfinite(*out);
}

/* The vertex index of a face token "i", "i/t", "i//n" or "i/t/n". */
static bool parse_index(const char *tok, size_t len, long long *out) {
    size_t n = 0;
    while (n < len && tok[n] != '/')
        n++;
    char buf[24];
    if (n == 0 || n >= sizeof buf)
        return false;
    memcpy(buf, tok, n);
    buf[n] = '\0';
    char *end;
    errno = 0;
    *out = strtoll(buf, &end, 10);
    return end == buf + n && errno == 0;
}

typedef struct parser {
    const char *name;
    grow verts, tris;
    const pfx_diag_at *at;
    long line;
} parser;

static bool parse_vertex(parser *p, const char *c, const char *end, double scale) {
    double v[3];
    for (int k = 0; k < 3; k++) {
        const char *tok;
        size_t len;
        char q[32];
        if (!next_token(&c, end, &tok, &len))
            return fail(p->at, PFX_RULE_INVALID_FILE, "'%s' line %ld: a vertex needs 3 coordinates",
                        p->name, p->line);
        if (!parse_double(tok, len, &v[k]))
            return fail(p->at, PFX_RULE_INVALID_FILE, "'%s' line %ld: '%s' is not a number",
                        p->name, p->line, quoted(tok, len, q));
        v[k] *= scale;
    }
    if (p->verts.count / 3 >= PFX_MESH_MAX_VERTICES)
        return fail(p->at, PFX_RULE_TOO_LARGE, "'%s' line %ld: more than %u vertices", p->name,
                    p->line, PFX_MESH_MAX_VERTICES);
    for (int k = 0; k < 3; k++)
        if (!grow_push(&p->verts, &v[k]))
            return fail(p->at, PFX_RULE_OUT_OF_MEMORY, "out of memory reading '%s'", p->name);
    return true;
}

/* A face of n >= 3 vertices becomes the fan (0, k - 1, k), k = 2..n-1. */
static bool parse_face(parser *p, const char *c, const char *end) {
    uint32_t nv = (uint32_t)(p->verts.count / 3), first = 0, prev = 0;
    int corners = 0;
    const char *tok;
    size_t len;
    while (next_token(&c, end, &tok, &len)) {
        long long i;
        char q[32];
        if (!parse_index(tok, len, &i))
            return fail(p->at, PFX_RULE_INVALID_FILE, "'%s' line %ld: '%s' is not a face index",
                        p->name, p->line, quoted(tok, len, q));
        long long idx = i > 0 ? i - 1 : (long long)nv + i;
        if (i == 0 || idx < 0 || idx >= (long long)nv)
            return fail(p->at, PFX_RULE_INVALID_FILE,
                        "'%s' line %ld: face index %lld is out of range (%u vertices)", p->name,
                        p->line, i, nv);
        uint32_t cur = (uint32_t)idx;
        if (corners == 0) {
            first = cur;
        } else if (corners >= 2) {
            if (p->tris.count / 3 >= PFX_MESH_MAX_TRIANGLES)
                return fail(p->at, PFX_RULE_TOO_LARGE, "'%s' line %ld: more than %u triangles",
                            p->name, p->line, PFX_MESH_MAX_TRIANGLES);
            uint32_t t[3] = {first, prev, cur};
            for (int k = 0; k < 3; k++)
                if (!grow_push(&p->tris, &t[k]))
                    return fail(p->at, PFX_RULE_OUT_OF_MEMORY, "out of memory reading '%s'",
                                p->name);
        }
        prev = cur;
        corners++;
    }
    if (corners < 3)
        return fail(p->at, PFX_RULE_INVALID_FILE, "'%s' line %ld: a face needs at least 3 vertices",
                    p->name, p->line);
    return true;
}

/* The area table and the copy into the arena, once the file is read. */
static bool finish(parser *p, pfx_arena *a, pfx_mesh *m) {
    size_t nt = p->tris.count / 3, nv = p->verts.count / 3;
    if (nt == 0)
        return fail(p->at, PFX_RULE_INVALID_FILE, "'%s' has no faces", p->name);
    double *verts = pfx_arena_alloc(a, nv * 3 * sizeof *verts);
    uint32_t *tris = pfx_arena_alloc(a, nt * 3 * sizeof *tris);
    double *cum = pfx_arena_alloc(a, nt * sizeof *cum);
    if (!verts || !tris || !cum)
        return fail(p->at, PFX_RULE_OUT_OF_MEMORY, "out of memory reading '%s'", p->name);
    memcpy(verts, p->verts.p, nv * 3 * sizeof *verts);
    memcpy(tris, p->tris.p, nt * 3 * sizeof *tris);
    double total = 0;
    for (size_t t = 0; t < nt; t++) {
        const double *A = verts + 3 * tris[3 * t], *B = verts + 3 * tris[3 * t + 1],
                     *C = verts + 3 * tris[3 * t + 2];
        double e1[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
        double e2[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
        double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2],
               z = e1[0] * e2[1] - e1[1] * e2[0];
        total += 0.5 * sqrt(x * x + y * y + z * z);
        cum[t] = total;
    }
    if (!isfinite(total))
        return fail(p->at, PFX_RULE_INVALID_FILE,
                    "the faces of '%s' have an infinite total area (coordinates too large)",
                    p->name);
    if (total <= 0)
        return fail(p->at, PFX_RULE_INVALID_FILE, "the faces of '%s' have zero total area",
                    p->name);
    m->verts = verts;
    m->tris = tris;
    m->cum = cum;
    m->vert_count = (uint32_t)nv;
    m->tri_count = (uint32_t)nt;
    return true;
}

bool pfx_mesh_parse(const char *text, size_t len, const char *name, double scale, pfx_arena *a,
                    pfx_mesh *m, const pfx_diag_at *at) {
    memset(m, 0, sizeof *m);
    parser p = {.name = name,
                .verts = {.elem = sizeof(double)},
                .tris = {.elem = sizeof(uint32_t)},
                .at = at};
    size_t pos = 0;
    if (len >= 3 && !memcmp(text, "\xEF\xBB\xBF", 3))
        pos = 3; /* a UTF-8 byte order mark */
    bool ok = true;
    while (ok && pos < len) {
        p.line++;
        const char *line = text + pos, *nl = memchr(line, '\n', len - pos);
        const char *end = nl ? nl : text + len;
        pos = (size_t)(end - text) + 1;
        const char *hash = memchr(line, '#', (size_t)(end - line));
        if (hash)
            end = hash;
        const char *c = line, *tok;
        size_t tl;
        if (!next_token(&c, end, &tok, &tl))
            continue;
        if (tl == 1 && tok[0] == 'v')
            ok = parse_vertex(&p, c, end, scale);
        else if (tl == 1 && tok[0] == 'f')
            ok = parse_face(&p, c, end);
        /* vt, vn, o, g, s, l, p, usemtl, mtllib, ...: not part of a surface */
    }
    if (ok)
        ok = finish(&p, a, m);
    free(p.verts.p);
    free(p.tris.p);
    return ok;
}

bool pfx_mesh_load(const char *path, const char *name, double scale, pfx_arena *a, pfx_mesh *m,
                   const pfx_diag_at *at) {
    memset(m, 0, sizeof *m);
    /* Non-blocking, so that a FIFO without a writer does not hang the
     * open; then only a regular file is read (not a FIFO, a device such as
     * /dev/zero, or a directory). */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return fail(at, PFX_RULE_MISSING_FILE, "cannot open '%s': %s", name, strerror(errno));
    struct stat st;
    int errnum = fstat(fd, &st) != 0 ? errno : 0;
    if (errnum || !S_ISREG(st.st_mode)) {
        close(fd);
        if (errnum)
            return fail(at, PFX_RULE_MISSING_FILE, "cannot open '%s': %s", name, strerror(errnum));
        return fail(at, PFX_RULE_INVALID_FILE, "cannot open '%s': not a regular file", name);
    }
    FILE *f = fcntl(fd, F_SETFL, 0) == 0 ? fdopen(fd, "rb") : NULL;
    if (!f) {
        errnum = errno;
        close(fd);
        return fail(at, PFX_RULE_MISSING_FILE, "cannot open '%s': %s", name, strerror(errnum));
    }
    char *buf = NULL;
    size_t len = 0, cap = 0;
    bool ok = true;
    /* Grow to at most one byte past the limit: reading that byte means too large. */
    for (;;) {
        if (len == cap) {
            if (len > PFX_MESH_MAX_BYTES) {
                ok = fail(at, PFX_RULE_TOO_LARGE, "'%s' is larger than %u MiB", name,
                          PFX_MESH_MAX_BYTES >> 20);
                break;
            }
            cap = cap ? 2 * cap : 1 << 16;
            if (cap > (size_t)PFX_MESH_MAX_BYTES + 1)
                cap = (size_t)PFX_MESH_MAX_BYTES + 1;
            char *p = realloc(buf, cap);
            if (!p) {
                ok = fail(at, PFX_RULE_OUT_OF_MEMORY, "out of memory reading '%s'", name);
                break;
            }
            buf = p;
        }
        size_t got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0) {
            if (ferror(f))
                ok = fail(at, PFX_RULE_READ_FAILED, "cannot read '%s': %s", name, strerror(errno));
            break;
        }
    }
    fclose(f);
    if (ok)
        ok = pfx_mesh_parse(buf ? buf : "", len, name, scale, a, m, at);
    free(buf);
    return ok;
}
