/* Loading an effect file: read it (bounded), parse it, compile it. The
 * only place that opens an effect file; compile works on the node tree. */
#include "jobs/load.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

static pfx_effect *load_source(pfx_loaded *l, const char *path, char *buf, size_t len,
                               const pfx_compile_options *opt);

pfx_effect *pfx_load(pfx_loaded *l, const char *path, const pfx_compile_options *opt) {
    memset(l, 0, sizeof *l);
    pfx_diags_init(&l->diags, path, NULL, 0);
    FILE *f = fopen(path, "rb");
    if (!f) {
        pfx_diag_add(&l->diags, PFX_SEV_ERROR, 0, 0, 0, PFX_RULE_MISSING_FILE,
                     "cannot open '%s': %s", path, strerror(errno));
        return NULL;
    }
    /* Read at most one byte past the limit, so a huge file costs bounded
     * memory and is reported rather than loaded. */
    size_t cap = 65536, len = 0;
    char *buf = malloc(cap + 1);
    while (buf) {
        if (len == cap) {
            if (cap > PFX_MAX_FILE_BYTES)
                break;
            cap *= 2;
            char *nb = realloc(buf, cap + 1);
            if (!nb) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = nb;
        }
        size_t got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0)
            break;
    }
    int read_errno = ferror(f) ? errno : 0;
    fclose(f);
    if (!buf || read_errno) {
        if (read_errno)
            pfx_diag_add(&l->diags, PFX_SEV_ERROR, 0, 0, 0, PFX_RULE_READ_FAILED,
                         "cannot read '%s': %s", path, strerror(read_errno));
        else
            pfx_diag_add(&l->diags, PFX_SEV_ERROR, 0, 0, 0, PFX_RULE_OUT_OF_MEMORY,
                         "cannot read '%s': out of memory", path);
        free(buf);
        return NULL;
    }
    return load_source(l, path, buf, len, opt);
}

pfx_effect *pfx_load_bytes(pfx_loaded *l, const char *path, const void *bytes, size_t len,
                           const pfx_compile_options *opt) {
    memset(l, 0, sizeof *l);
    pfx_diags_init(&l->diags, path, NULL, 0);
    char *buf = malloc(len + 1);
    if (!buf) {
        pfx_diag_add(&l->diags, PFX_SEV_ERROR, 0, 0, 0, PFX_RULE_OUT_OF_MEMORY,
                     "cannot read '%s': out of memory", path);
        return NULL;
    }
    if (len)
        memcpy(buf, bytes, len);
    return load_source(l, path, buf, len, opt);
}

/* The checks and stages after reading: buf (malloc'd, len bytes, room for
 * one more) becomes l->source. */
static pfx_effect *load_source(pfx_loaded *l, const char *path, char *buf, size_t len,
                               const pfx_compile_options *opt) {
    buf[len] = 0;
    l->source = buf;
    l->source_len = len;
    l->diags.source = buf;
    l->diags.source_len = len;
    if (len > PFX_MAX_FILE_BYTES) {
        pfx_diag_add(&l->diags, PFX_SEV_ERROR, 0, 0, 0, PFX_RULE_TOO_LARGE,
                     "the file is larger than %u MiB; an effect file is a few kilobytes",
                     PFX_MAX_FILE_BYTES >> 20);
        return NULL;
    }
    const char *nul = memchr(buf, 0, len);
    if (nul) {
        int line = 1, col = 1;
        for (const char *p = buf; p < nul; p++) {
            if (*p == '\n')
                line++, col = 1;
            else if (((unsigned char)*p & 0xc0) != 0x80)
                col++;
        }
        pfx_diag_add(&l->diags, PFX_SEV_ERROR, line, col, 1, PFX_RULE_NOT_UTF8,
                     "the file contains NUL bytes; an effect file is UTF-8 text");
        return NULL;
    }
    if (!pfx_parse(buf, len, &l->doc, &l->diags))
        return NULL;
    if (opt && opt->set_count &&
        !pfx_overrides_apply(&l->overrides, &l->doc, path, opt->sets, opt->set_count))
        return NULL;
    l->effect = pfx_compile(l->doc.root, path, opt, &l->arena, &l->diags);
    pfx_overrides_claim(&l->overrides, &l->diags);
    return l->effect;
}

void pfx_loaded_free(pfx_loaded *l) {
    pfx_doc_free(&l->doc);
    pfx_arena_free(&l->arena);
    pfx_diags_free(&l->diags);
    pfx_overrides_free(&l->overrides);
    free(l->source);
    memset(l, 0, sizeof *l);
}

void pfx_loaded_print(const pfx_loaded *l, FILE *out, bool json) {
    pfx_diags_print(&l->overrides.diags, out, json);
    pfx_diags_print(&l->diags, out, json);
}

int pfx_loaded_warnings(const pfx_loaded *l) {
    return l->diags.warnings + l->overrides.diags.warnings;
}
