/* The gathering of jobs/assemble.h. Every frame is checked against the
 * hash its slice recorded before it is linked, so a slice that a node
 * crashed in the middle of (a manifest older than its frames, or a frame
 * damaged in transfer) is caught here, not in the film. A frame lands in
 * out under a temporary name and is renamed, as render writes it
 * (output/atomic_file.h). */
#include "jobs/assemble.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/regular_file.h"
#include "base/sha256.h"
#include "base/strmap.h"
#include "jobs/atlas_job.h"
#include "jobs/manifest.h"
#include "jobs/motion_job.h"
#include "jobs/preview.h"
#include "output/atomic_file.h"

#define SLICE_MARK ".slice-"
#define MANIFEST_SUFFIX ".manifest.json"

typedef struct part {
    char *stem; /* the render's name: fire */
    char *dir;  /* where the slice's frames are */
    char *path; /* its manifest */
    pfx_manifest *m;
} part;

typedef struct parts {
    part *items;
    size_t count, cap;
} parts;

static void parts_free(parts *p) {
    for (size_t i = 0; i < p->count; i++) {
        free(p->items[i].stem);
        free(p->items[i].dir);
        free(p->items[i].path);
        pfx_manifest_destroy(p->items[i].m);
    }
    free(p->items);
}

/* "fire.slice-0003-of-0008.manifest.json" -> stem "fire". */
static char *slice_stem(const char *name) {
    size_t len = strlen(name), suf = strlen(MANIFEST_SUFFIX);
    const char *mark = strstr(name, SLICE_MARK);
    if (name[0] == '.' || len <= suf || strcmp(name + len - suf, MANIFEST_SUFFIX) || !mark ||
        mark == name)
        return NULL;
    return strndup(name, (size_t)(mark - name));
}

static bool scan_dir(const char *dir, parts *p, pfx_diags *d) {
    DIR *dh = opendir(dir);
    if (!dh) {
        pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot read '%s': %s", dir, strerror(errno));
        return false;
    }
    bool ok = true;
    struct dirent *ent;
    while ((ent = readdir(dh)) && ok) {
        char *stem = slice_stem(ent->d_name);
        if (!stem)
            continue;
        if (p->count == p->cap) {
            size_t cap = p->cap ? 2 * p->cap : 16;
            part *items = realloc(p->items, cap * sizeof *items);
            if (!items) {
                free(stem);
                pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
                ok = false;
                break;
            }
            p->items = items;
            p->cap = cap;
        }
        part *it = &p->items[p->count++];
        *it = (part){.stem = stem, .dir = strdup(dir)};
        size_t n = strlen(dir) + strlen(ent->d_name) + 2;
        it->path = malloc(n);
        if (!it->dir || !it->path) {
            pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
            ok = false;
            break;
        }
        snprintf(it->path, n, "%s/%s", dir, ent->d_name);
        it->m = pfx_manifest_load(it->path, d);
        ok = it->m != NULL;
    }
    closedir(dh);
    return ok;
}

static int by_stem_then_path(const void *a, const void *b) {
    const part *x = a, *y = b;
    int c = strcmp(x->stem, y->stem);
    return c ? c : strcmp(x->path, y->path);
}

/* Copies the file open at fd (read from its start) to dst through a
 * temporary (output/atomic_file.h); src names it in messages. */
static bool copy_file(int fd, const char *src, const char *dst, pfx_diags *d) {
    if (lseek(fd, 0, SEEK_SET) != 0) {
        pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot read '%s': %s", src, strerror(errno));
        return false;
    }
    pfx_atomic_file *a = pfx_atomic_open(dst, d);
    if (!a)
        return false;
    FILE *out = pfx_atomic_stream(a);
    char buf[1 << 16];
    ssize_t n;
    while ((n = read(fd, buf, sizeof buf)) != 0) {
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot read '%s': %s", src, strerror(errno));
            pfx_atomic_abort(a);
            return false;
        }
        if (fwrite(buf, 1, (size_t)n, out) != (size_t)n) {
            pfx_atomic_failed(a, errno);
            break;
        }
    }
    return pfx_atomic_commit(a, false, d);
}

/* Puts dir/name into out/name, checked against sha256. name is a plain
 * name from the checked, merged list (pfx_manifest_assemble), so out/name
 * is in out; the source must be a regular file, not a link (a slice's
 * directory is input: a FIFO or a link to /dev/zero would hang the hash,
 * a link elsewhere would copy a file the slice does not own). */
static bool gather(const char *dir, const char *name, const char *sha256, const char *out,
                   pfx_assemble_report *r, pfx_diags *d) {
    char src[4096], dst[4096], hex[PFX_SHA256_HEX];
    if (!pfx_manifest_plain_name(name)) { /* pfx_manifest_assemble refused it already */
        pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                       "'%s' lists an output that is not a plain "
                       "file name",
                       dir);
        return false;
    }
    snprintf(src, sizeof src, "%s/%s", dir, name);
    snprintf(dst, sizeof dst, "%s/%s", out, name);
    int fd = pfx_open_regular(src, false);
    if (fd < 0 || !pfx_sha256_fd(fd, hex)) {
        pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot read '%s': %s", src,
                       pfx_file_strerror(errno));
        if (fd >= 0)
            close(fd);
        return false;
    }
    bool ok = true;
    if (strcmp(hex, sha256)) {
        pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                       "'%s' does not match the hash its slice's manifest records", src);
        ok = false;
    } else if (pfx_sha256_file(dst, hex) && !strcmp(hex, sha256)) {
        r->kept++;
    } else {
        /* A hard link where the file system allows it, else a copy. */
        int linked = pfx_atomic_link(src, dst, d);
        if (linked < 0 || (!linked && !copy_file(fd, src, dst, d)))
            ok = false;
        else if (linked)
            r->linked++;
        else
            r->copied++;
    }
    close(fd);
    return ok;
}

/* Whether the sorted outputs of m list name: a binary search, as
 * pfx_manifest_assemble sorts them by strcmp. */
static bool lists(const pfx_manifest *m, const char *name) {
    size_t lo = 0, hi = pfx_manifest_output_count(m);
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        int c = strcmp(pfx_manifest_output(m, mid, NULL), name);
        if (!c)
            return true;
        if (c < 0)
            lo = mid + 1;
        else
            hi = mid;
    }
    return false;
}

/* Every frame of first..last exactly once and nothing else: the colour
 * frames in the slices' format and, with --motion-vectors, their motion
 * vectors. Names are unique (pfx_manifest_assemble), so the right count
 * with every name listed is the whole check. */
static bool check_frames(const pfx_manifest *all, const char *stem, long first, long last,
                         const char *ext, bool motion, pfx_diags *d) {
    const size_t frames = (size_t)(last - first + 1), want = motion ? 2 * frames : frames;
    if (pfx_manifest_output_count(all) != want) {
        pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                       "the slices of '%s' hold %zu files for the %zu frames %ld to %ld%s", stem,
                       pfx_manifest_output_count(all), frames, first, last,
                       motion ? " and their motion vectors" : "");
        return false;
    }
    for (long f = first; f <= last; f++) {
        char name[300];
        snprintf(name, sizeof name, "%s_%04ld.%s", stem, f, ext);
        if (!lists(all, name)) {
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES, "frame %ld of '%s' is in no slice", f,
                           stem);
            return false;
        }
        snprintf(name, sizeof name, "%s_mv_%04ld.png", stem, f);
        if (motion && !lists(all, name)) {
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                           "the motion vectors of frame %ld of '%s' are in no slice", f, stem);
            return false;
        }
    }
    return true;
}

/* The slices' frame format, from the first frame's name (render --format;
 * colour frames sort before STEM_mv_...): "exr" or "png". */
static const char *frame_ext(const pfx_manifest *all) {
    const char *name = pfx_manifest_output_count(all) ? pfx_manifest_output(all, 0, NULL) : NULL;
    const size_t len = name ? strlen(name) : 0;
    return len > 4 && !strcmp(name + len - 4, ".exr") ? "exr" : "png";
}

/* The merged manifest of parts p[0..n), with its frame range; with
 * --motion-vectors also their encoding in *mv (NULL when off). */
static pfx_manifest *merge_parts(part *p, size_t n, long *first, long *last, pfx_mv_meta *mv,
                                 const pfx_mv_meta **motion, pfx_diags *d) {
    pfx_manifest **ms = malloc(n * sizeof *ms);
    const char **names = malloc(n * sizeof *names);
    pfx_manifest *all = NULL;
    if (!ms || !names)
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
    for (size_t i = 0; ms && names && i < n; i++) {
        ms[i] = p[i].m;
        names[i] = p[i].path;
    }
    if (ms && names)
        all = pfx_manifest_assemble(ms, names, n, first, last, d);
    *motion = NULL;
    if (all && pfx_manifest_get_number(all, "motion_vectors", 0) != 0) {
        if (pfx_mv_assembled(all, ms, names, n, mv, d)) {
            *motion = mv;
        } else {
            pfx_manifest_destroy(all);
            all = NULL;
        }
    }
    free(ms);
    free(names);
    return all;
}

/* Gathers every output of the merged list `all` (names checked by
 * pfx_manifest_assemble, never a part's own list) from the part that
 * lists it: a map from name to part keeps this O(outputs). */
static bool gather_all(const part *p, size_t n, const pfx_manifest *all, const char *out,
                       pfx_assemble_report *r, pfx_diags *d) {
    pfx_strmap from;
    pfx_strmap_init(&from);
    bool ok = true, found;
    for (size_t i = 0; ok && i < n; i++)
        for (size_t k = 0; ok && k < pfx_manifest_output_count(p[i].m); k++) {
            const char *name = pfx_manifest_output(p[i].m, k, NULL);
            if (name && !pfx_strmap_add(&from, name, strlen(name), i, &found)) {
                pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
                ok = false;
            }
        }
    for (size_t k = 0; ok && k < pfx_manifest_output_count(all); k++) {
        const char *sha, *name = pfx_manifest_output(all, k, &sha);
        const size_t *i = pfx_strmap_get(&from, name, strlen(name));
        if (!i) /* cannot happen: the merged list is made of the parts' lists */
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES, "no slice lists '%s'", name);
        ok = i && gather(p[*i].dir, name, sha, out, r, d);
    }
    pfx_strmap_free(&from);
    return ok;
}

/* A slice's fps and image size as render accepts them (the effect file's
 * bounds), and the same in every slice of a render (p[0..n) share a
 * stem): read from files that are input, checked before any frame is
 * gathered rather than failing in the preview or the atlas. */
static bool check_settings(const part *p, size_t n, pfx_diags *d) {
    bool ok = true;
    for (size_t i = 0; i < n; i++) {
        double fps = pfx_manifest_get_number(p[i].m, "fps", NAN);
        double w = pfx_manifest_get_number(p[i].m, "width", NAN);
        double h = pfx_manifest_get_number(p[i].m, "height", NAN);
        if (isnan(fps)) {
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES, "'%s' records no fps (a number)",
                           p[i].path);
            ok = false;
        } else if (!(fps > 0 && fps <= PFX_MAX_FPS)) {
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                           "'%s' records fps %g; it must be greater than 0 and at most %g",
                           p[i].path, fps, PFX_MAX_FPS);
            ok = false;
        } else if (i > 0 && fps != pfx_manifest_get_number(p[0].m, "fps", NAN)) {
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                           "'%s' records fps %g, and '%s' fps %g: slices of one render share "
                           "their fps",
                           p[i].path, fps, p[0].path, pfx_manifest_get_number(p[0].m, "fps", 0));
            ok = false;
        }
        if (!(w >= 1 && w <= PFX_MAX_IMAGE_SIDE && w == floor(w) && h >= 1 &&
              h <= PFX_MAX_IMAGE_SIDE && h == floor(h) && w * h <= (double)PFX_MAX_IMAGE_PIXELS)) {
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                           "'%s' records an image size of %gx%g, not one render can make",
                           p[i].path, w, h);
            ok = false;
        }
    }
    return ok;
}

/* One render: parts p[0..n) share a stem. */
static bool assemble_one(part *p, size_t n, const char *out, const pfx_assemble_options *opt,
                         pfx_assemble_report *r, pfx_diags *d) {
    long first = 0, last = -1;
    pfx_mv_meta mv;
    const pfx_mv_meta *motion;
    pfx_manifest *all = merge_parts(p, n, &first, &last, &mv, &motion, d);
    if (!all)
        return false;
    const char *ext = frame_ext(all);
    bool ok = check_frames(all, p[0].stem, first, last, ext, motion != NULL, d);
    if (ok && !strcmp(ext, "exr") && (opt->atlas || opt->preview)) {
        pfx_diag_error(d, PFX_RULE_IMPOSSIBLE_REQUEST,
                       "the slices of '%s' are EXR frames; %s is built from PNG frames", p[0].stem,
                       opt->atlas ? "--atlas" : "--preview");
        ok = false;
    }
    /* A preview the frames cannot go into fails before any is gathered. */
    const pfx_preview size_check = {.path = opt->preview};
    ok = ok && (!opt->preview ||
                pfx_preview_check(&size_check, (int)pfx_manifest_get_number(all, "width", 0),
                                  (int)pfx_manifest_get_number(all, "height", 0), d));
    ok = ok && gather_all(p, n, all, out, r, d);
    /* The atlas (with the motion-vector sheet), the motion-vector sidecar
     * and the preview as render makes them, and in its settings, so that
     * the key is the one a single render with them would have. */
    double fps = pfx_manifest_get_number(all, "fps", 30);
    bool loop = pfx_manifest_get_number(all, "loop", 0) != 0;
    bool premultiplied = pfx_manifest_get_number(all, "premultiplied", 0) != 0;
    if (ok && opt->atlas) {
        pfx_atlas_layout atlas = *opt->atlas;
        atlas.motion = motion;
        atlas.premultiplied = premultiplied;
        atlas.frame_w = (int)pfx_manifest_get_number(all, "width", 0);
        atlas.frame_h = (int)pfx_manifest_get_number(all, "height", 0);
        pfx_atlas_job_describe(&atlas, all);
        ok = pfx_atlas_job_run(out, p[0].stem, first, last, 1, fps, loop, &atlas, all, d);
    } else if (ok && motion) {
        ok = pfx_mv_sidecar_run(out, p[0].stem, first, last, motion, all, d);
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/%s.manifest.json", out, p[0].stem);
    pfx_manifest *prev = ok ? pfx_manifest_read(path) : NULL;
    if (ok && opt->preview) {
        /* Made again unless the last assembly of the same frames and
         * settings recorded it and it still has that hash: a preview
         * damaged since is never taken for done. */
        pfx_preview preview = {
            .path = opt->preview, .quality = opt->preview_quality, .premultiplied = premultiplied};
        pfx_manifest_set_string(all, "preview", opt->preview);
        if (opt->preview_quality >= 0)
            pfx_manifest_set_number(all, "preview_quality", opt->preview_quality);
        const char *key = pfx_manifest_key(all),
                   *was = prev ? pfx_manifest_recorded_key(prev) : NULL;
        const bool intact =
            key && was && !strcmp(key, was) && pfx_manifest_preview_intact(prev, opt->preview);
        if (intact) /* hashed just now: its hash is the one recorded */
            pfx_manifest_keep_preview(all, prev);
        else
            ok = pfx_preview_run(out, p[0].stem, first, last, 1, fps,
                                 (int)pfx_manifest_get_number(all, "width", 0),
                                 (int)pfx_manifest_get_number(all, "height", 0), &preview, d) &&
                 pfx_manifest_add_preview(all, opt->preview, d);
    }
    pfx_manifest_key(all);
    if (ok) {
        if (prev)
            pfx_manifest_remove_stale(prev, all, out, d);
        ok = pfx_manifest_write(all, path, d);
    }
    pfx_manifest_destroy(prev);
    if (ok) {
        r->effects++;
        r->frames += (size_t)(last - first + 1);
    }
    pfx_manifest_destroy(all);
    return ok;
}

bool pfx_assemble(const char *const *dirs, size_t n, const char *out,
                  const pfx_assemble_options *opt, pfx_assemble_report *r, pfx_diags *d) {
    *r = (pfx_assemble_report){0};
    parts p = {0};
    bool ok = true;
    for (size_t i = 0; i < n && ok; i++)
        ok = scan_dir(dirs[i], &p, d);
    if (ok && p.count == 0) {
        pfx_diag_error(d, PFX_RULE_MISSING_FILE,
                       "no slice manifests (NAME.slice-I-of-N.manifest.json) in the "
                       "directories given");
        ok = false;
    }
    if (ok) {
        qsort(p.items, p.count, sizeof *p.items, by_stem_then_path);
        if (opt->preview && strcmp(p.items[0].stem, p.items[p.count - 1].stem)) {
            pfx_diag_error(d, PFX_RULE_IMPOSSIBLE_REQUEST,
                           "--preview names one file, and the slices are of '%s' and '%s'",
                           p.items[0].stem, p.items[p.count - 1].stem);
            ok = false;
        }
    }
    /* Every render's settings first, then the work. */
    for (int pass = 0; ok && pass < 2; pass++)
        for (size_t i = 0; i < p.count;) {
            size_t j = i + 1;
            while (j < p.count && !strcmp(p.items[j].stem, p.items[i].stem))
                j++;
            if (pass == 0)
                ok = check_settings(p.items + i, j - i, d) && ok;
            else
                ok = assemble_one(p.items + i, j - i, out, opt, r, d) && ok;
            i = j;
        }
    parts_free(&p);
    return ok;
}
