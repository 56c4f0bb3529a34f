/* Manifests (jobs/manifest.h) as jansson objects: built up by the command,
 * written atomically, read back to decide whether a run has anything to do
 * and which files of the previous run are stale. The bake key is the
 * SHA-256 of a canonical dump (sorted keys, compact) of the version, the
 * results revision, the command, settings and inputs: never of the
 * outputs, which it predicts. */
#include "jobs/manifest.h"

#include <errno.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/json_text.h"
#include "base/regular_file.h"
#include "base/strmap.h"
#include "jobs/input_files.h"
#include "output/json_file.h"

#define MANIFEST_FORMAT 1

struct pfx_manifest {
    json_t *root; /* format, pfx_version, pfx_results, command, settings, inputs, bake_key,
                     outputs */
    char key[PFX_SHA256_HEX];
    /* The outputs by path -> index in "outputs", built at the first lookup
     * and kept up to date by appends, so that listing, merging and
     * comparing n outputs is O(n), not O(n^2) (100k frames). Keys point
     * into the JSON strings, which live as long as their entries. */
    pfx_strmap index;
    bool indexed;
};

static json_t *member(const pfx_manifest *m, const char *k) { return json_object_get(m->root, k); }

pfx_manifest *pfx_manifest_create(const char *command) {
    pfx_manifest *m = calloc(1, sizeof *m);
    if (!m)
        return NULL;
    m->root = json_pack("{s:i, s:s, s:i, s:s, s:{}, s:[], s:[]}", "pfx_manifest", MANIFEST_FORMAT,
                        "pfx_version", PFX_VERSION, "pfx_results", PFX_RESULTS, "command", command,
                        "settings", "inputs", "outputs");
    if (!m->root) {
        free(m);
        return NULL;
    }
    return m;
}

void pfx_manifest_destroy(pfx_manifest *m) {
    if (!m)
        return;
    pfx_strmap_free(&m->index);
    json_decref(m->root);
    free(m);
}

/* Drops the index after the outputs were reordered or replaced. */
static void index_drop(pfx_manifest *m) {
    pfx_strmap_free(&m->index);
    m->indexed = false;
}

/* The output entry of m named path, or NULL: O(1) through the index (also
 * NULL, harmlessly, when the index cannot be allocated: the callers then
 * append a duplicate, which assemble and the up-to-date check refuse or
 * tolerate). A later duplicate path keeps the first entry's index. */
static json_t *find_output(const pfx_manifest *cm, const char *path) {
    pfx_manifest *m = (pfx_manifest *)cm; /* the index is a cache */
    json_t *outputs = member(m, "outputs");
    if (!m->indexed) {
        pfx_strmap_init(&m->index);
        m->indexed = true;
        for (size_t i = 0; i < json_array_size(outputs); i++) {
            const char *p = json_string_value(json_object_get(json_array_get(outputs, i), "path"));
            bool found;
            if (p && !pfx_strmap_add(&m->index, p, strlen(p), i, &found)) {
                index_drop(m);
                return NULL;
            }
        }
    }
    const size_t *at = pfx_strmap_get(&m->index, path, strlen(path));
    return at ? json_array_get(outputs, *at) : NULL;
}

/* Appends {path, sha256} to m's outputs and to the index. */
static void append_output(pfx_manifest *m, const char *path, const char *sha256) {
    json_t *outputs = member(m, "outputs");
    json_t *o = json_pack("{s:o, s:s}", "path", pfx_json_bytes(path), "sha256", sha256);
    if (!o || json_array_append_new(outputs, o) != 0)
        return;
    bool found;
    const char *key = json_string_value(json_object_get(o, "path"));
    if (m->indexed &&
        !pfx_strmap_add(&m->index, key, strlen(key), json_array_size(outputs) - 1, &found))
        index_drop(m);
}

void pfx_manifest_set_string(pfx_manifest *m, const char *key, const char *value) {
    json_object_set_new(member(m, "settings"), key, pfx_json_bytes(value));
}

/* Whole numbers as JSON integers, so that 30 reads as 30 and not 30.0. */
void pfx_manifest_set_number(pfx_manifest *m, const char *key, double value) {
    json_t *v =
        value == (double)(json_int_t)value ? json_integer((json_int_t)value) : json_real(value);
    json_object_set_new(member(m, "settings"), key, v);
}

void pfx_manifest_set_strings(pfx_manifest *m, const char *key, const char *const *values,
                              size_t n) {
    json_t *list = json_array();
    for (size_t i = 0; i < n; i++)
        json_array_append_new(list, json_string(values[i]));
    json_object_set_new(member(m, "settings"), key, list);
}

void pfx_manifest_set_range(pfx_manifest *m, const char *key, long first, long last) {
    json_object_set_new(member(m, "settings"), key,
                        json_pack("[I, I]", (json_int_t)first, (json_int_t)last));
}

double pfx_manifest_get_number(const pfx_manifest *m, const char *key, double fallback) {
    json_t *v = json_object_get(member(m, "settings"), key);
    return json_is_number(v) ? json_number_value(v) : fallback;
}

static json_t *find_path(json_t *list, const char *path) {
    size_t i;
    json_t *v;
    json_array_foreach(list, i, v) {
        const char *p = json_string_value(json_object_get(v, "path"));
        if (p && !strcmp(p, path))
            return v;
    }
    return NULL;
}

bool pfx_manifest_add_input(pfx_manifest *m, const char *path, pfx_diags *d) {
    if (find_path(member(m, "inputs"), path))
        return true;
    char hex[PFX_SHA256_HEX];
    if (!pfx_sha256_file(path, hex)) {
        pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot read input '%s': %s", path,
                       pfx_file_strerror(errno));
        return false;
    }
    pfx_manifest_add_input_sha256(m, path, hex);
    return true;
}

void pfx_manifest_add_input_sha256(pfx_manifest *m, const char *path, const char *sha256) {
    json_t *inputs = member(m, "inputs");
    if (!find_path(inputs, path))
        json_array_append_new(
            inputs, json_pack("{s:o, s:s}", "path", pfx_json_bytes(path), "sha256", sha256));
}

void pfx_effect_each_input(const pfx_effect *e, void (*fn)(void *ctx, const char *path),
                           void *ctx) {
    fn(ctx, e->path);
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        if (em->shape.file)
            fn(ctx, em->shape.file);
        /* Textures and normal maps are inputs too: editing one must make
         * the run stale and re-run a build that reads the depfile. */
        const pfx_image *maps[2] = {em->look.texture, em->look.normal_map};
        for (int k = 0; k < 2; k++)
            if (maps[k] && maps[k]->file)
                fn(ctx, maps[k]->file);
    }
}

typedef struct add_inputs {
    pfx_manifest *m;
    pfx_diags *d;
    bool ok;
} add_inputs;

static void add_one_input(void *ctx, const char *path) {
    add_inputs *a = ctx;
    a->ok = pfx_manifest_add_input(a->m, path, a->d) && a->ok;
}

bool pfx_manifest_add_effect(pfx_manifest *m, const pfx_effect *e, pfx_diags *d) {
    add_inputs a = {m, d, true};
    pfx_effect_each_input(e, add_one_input, &a);
    return a.ok;
}

size_t pfx_manifest_input_count(const pfx_manifest *m) {
    return json_array_size(member(m, "inputs"));
}

const char *pfx_manifest_input(const pfx_manifest *m, size_t i) {
    return json_string_value(json_object_get(json_array_get(member(m, "inputs"), i), "path"));
}

/* Member k, or null where m has none (an assembled manifest whose slices
 * came from a build that recorded no pfx_results). */
static json_t *member_or_null(const pfx_manifest *m, const char *k) {
    json_t *v = member(m, k);
    return v ? v : json_null();
}

const char *pfx_manifest_key(pfx_manifest *m) {
    json_t *keyed =
        json_pack("{s:O, s:O, s:O, s:O, s:O}", "pfx_version", member_or_null(m, "pfx_version"),
                  "pfx_results", member_or_null(m, "pfx_results"), "command", member(m, "command"),
                  "settings", member(m, "settings"), "inputs", member(m, "inputs"));
    json_t *escaped = keyed ? pfx_json_escaped(keyed) : NULL;
    char *text = escaped ? json_dumps(escaped, JSON_SORT_KEYS | JSON_COMPACT) : NULL;
    json_decref(escaped);
    json_decref(keyed);
    if (!text)
        return NULL;
    pfx_sha256_bytes(text, strlen(text), m->key);
    free(text);
    json_object_set_new(m->root, "bake_key", json_string(m->key));
    return m->key;
}

bool pfx_manifest_add_output(pfx_manifest *m, const char *dir, const char *name, pfx_diags *d) {
    char path[4096], hex[PFX_SHA256_HEX];
    int n = snprintf(path, sizeof path, "%s/%s", dir, name);
    if (n < 0 || (size_t)n >= sizeof path) {
        pfx_diag_error(d, PFX_RULE_TOO_LARGE, "output path '%s/%s' is too long", dir, name);
        return false;
    }
    if (!pfx_sha256_file(path, hex)) {
        pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot read output '%s': %s", path,
                       pfx_file_strerror(errno));
        return false;
    }
    json_t *old = find_output(m, name);
    if (old)
        json_object_set_new(old, "sha256", json_string(hex));
    else
        append_output(m, name, hex);
    return true;
}

bool pfx_manifest_add_preview(pfx_manifest *m, const char *path, pfx_diags *d) {
    char hex[PFX_SHA256_HEX];
    if (!pfx_sha256_file(path, hex)) {
        pfx_diag_error(d, PFX_RULE_READ_FAILED, "cannot read the preview '%s': %s", path,
                       pfx_file_strerror(errno));
        return false;
    }
    json_object_set_new(m->root, "preview",
                        json_pack("{s:o, s:s}", "path", pfx_json_bytes(path), "sha256", hex));
    return true;
}

bool pfx_manifest_preview_intact(const pfx_manifest *m, const char *path) {
    json_t *p = member(m, "preview");
    const char *recorded = json_string_value(json_object_get(p, "path"));
    const char *sha = json_string_value(json_object_get(p, "sha256"));
    char hex[PFX_SHA256_HEX];
    return path && recorded && sha && !strcmp(recorded, path) && pfx_sha256_file(path, hex) &&
           !strcmp(hex, sha);
}

size_t pfx_manifest_output_count(const pfx_manifest *m) {
    return json_array_size(member(m, "outputs"));
}

const char *pfx_manifest_output(const pfx_manifest *m, size_t i, const char **sha256) {
    json_t *o = json_array_get(member(m, "outputs"), i);
    if (sha256)
        *sha256 = json_string_value(json_object_get(o, "sha256"));
    return json_string_value(json_object_get(o, "path"));
}

bool pfx_manifest_write(pfx_manifest *m, const char *path, pfx_diags *d) {
    if (!member(m, "bake_key"))
        pfx_manifest_key(m);
    return pfx_json_file_write(path, m->root, d);
}

/* Whether every entry of list is {path: string, sha256: string}, as pfx
 * writes them, so that no reader meets a NULL path (a depfile, a key). */
static bool all_files(json_t *list) {
    size_t i;
    json_t *v;
    json_array_foreach(list, i, v) {
        if (!json_is_string(json_object_get(v, "path")) ||
            !json_is_string(json_object_get(v, "sha256")))
            return false;
    }
    return json_is_array(list);
}

/* The reading of pfx_manifest_read; when d is given, why the file is not
 * a manifest goes there (the JSON error with its line and column). */
static pfx_manifest *read_manifest(const char *path, pfx_diags *d) {
    int fd = pfx_open_regular(path, true);
    FILE *f = fd >= 0 ? fdopen(fd, "rb") : NULL;
    int err = errno;
    if (!f && fd >= 0)
        close(fd);
    json_error_t jerr;
    json_t *root = f ? json_loadf(f, 0, &jerr) : NULL;
    if (f)
        fclose(f);
    if (!f && d)
        pfx_diag_error(d, PFX_RULE_INVALID_FILE, "'%s' is not a pfx manifest: %s", path,
                       pfx_file_strerror(err));
    else if (!root && d)
        pfx_diag_error(d, PFX_RULE_INVALID_FILE, "'%s' is not a pfx manifest: %s:%d:%d: %s", path,
                       path, jerr.line, jerr.column, jerr.text);
    pfx_json_unescape(root);
    json_t *format = json_object_get(root, "pfx_manifest");
    if (root && (!json_is_integer(format) || json_integer_value(format) != MANIFEST_FORMAT ||
                 !all_files(json_object_get(root, "outputs")) ||
                 !all_files(json_object_get(root, "inputs")) ||
                 !json_is_object(json_object_get(root, "settings")))) {
        if (d)
            pfx_diag_error(d, PFX_RULE_INVALID_FILE,
                           "'%s' is not a pfx manifest: not format %d with settings, and inputs "
                           "and outputs of a path and a sha256 each",
                           path, MANIFEST_FORMAT);
        json_decref(root);
        return NULL;
    }
    if (!root)
        return NULL;
    pfx_manifest *m = calloc(1, sizeof *m);
    if (!m) {
        if (d)
            pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        json_decref(root);
        return NULL;
    }
    m->root = root;
    return m;
}

pfx_manifest *pfx_manifest_read(const char *path) { return read_manifest(path, NULL); }

pfx_manifest *pfx_manifest_load(const char *path, pfx_diags *d) { return read_manifest(path, d); }

const char *pfx_manifest_recorded_key(const pfx_manifest *m) {
    return json_string_value(member(m, "bake_key"));
}

bool pfx_manifest_plain_name(const char *name) {
    if (!name || !*name || name[0] == '.')
        return false;
    size_t n = 0;
    for (const unsigned char *c = (const unsigned char *)name; *c; c++, n++)
        if (*c == '/' || *c == '\\' || *c < 0x20 || *c == 0x7f)
            return false;
    return n <= 255;
}

/* 64 lowercase hex digits. */
static bool is_sha256(const char *hex) {
    if (!hex || strlen(hex) != PFX_SHA256_HEX - 1)
        return false;
    return strspn(hex, "0123456789abcdef") == PFX_SHA256_HEX - 1;
}

static bool plain_name(const char *name) { return pfx_manifest_plain_name(name); }

static bool file_has(const char *dir, const char *name, const char *sha256) {
    char path[4096], hex[PFX_SHA256_HEX];
    int n = snprintf(path, sizeof path, "%s/%s", dir, name);
    return n > 0 && (size_t)n < sizeof path && sha256 && pfx_sha256_file(path, hex) &&
           !strcmp(hex, sha256);
}

bool pfx_manifest_up_to_date(const pfx_manifest *prev, const char *key, const char *dir) {
    const char *recorded = pfx_manifest_recorded_key(prev);
    if (!recorded || !key || strcmp(recorded, key) || pfx_manifest_output_count(prev) == 0)
        return false;
    for (size_t i = 0; i < pfx_manifest_output_count(prev); i++) {
        const char *sha, *name = pfx_manifest_output(prev, i, &sha);
        if (!plain_name(name) || !file_has(dir, name, sha))
            return false;
    }
    /* A manifest from before previews were hashed records none: not up to
     * date, so the preview is made again and hashed. */
    const char *preview = json_string_value(json_object_get(member(prev, "settings"), "preview"));
    return !preview || pfx_manifest_preview_intact(prev, preview);
}

size_t pfx_manifest_remove_stale(const pfx_manifest *prev, const pfx_manifest *now, const char *dir,
                                 pfx_diags *d) {
    size_t removed = 0;
    /* A frame of an earlier run can be this run's texture: stale by the
     * manifest, it is still read, so it stays. */
    pfx_input_files inputs;
    if (!pfx_input_files_of(now, &inputs)) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        return 0;
    }
    for (size_t i = 0; i < pfx_manifest_output_count(prev); i++) {
        const char *sha, *name = pfx_manifest_output(prev, i, &sha);
        if (!plain_name(name) || find_output(now, name))
            continue;
        char path[4096];
        int n = snprintf(path, sizeof path, "%s/%s", dir, name);
        if (n < 0 || (size_t)n >= sizeof path || access(path, F_OK) != 0)
            continue;
        if (!file_has(dir, name, sha)) {
            pfx_diag_note(d, 0, 0, 1, "kept stale '%s': it changed since pfx wrote it", path);
            continue;
        }
        if (pfx_input_files_find(&inputs, path)) {
            pfx_diag_note(d, 0, 0, 1, "kept stale '%s': it is an input of this run", path);
            continue;
        }
        if (unlink(path) == 0)
            removed++;
        else
            pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot remove stale '%s': %s", path,
                           strerror(errno));
    }
    pfx_input_files_free(&inputs);
    return removed;
}

static bool merge_outputs(pfx_manifest *dst, const pfx_manifest *src, const char *src_name,
                          pfx_diags *d);

void pfx_manifest_set_slice(pfx_manifest *m, long index, long count, long first, long last) {
    json_object_set_new(m->root, "slice",
                        json_pack("{s:I, s:I, s:[I, I]}", "index", (json_int_t)index, "count",
                                  (json_int_t)count, "frames", (json_int_t)first,
                                  (json_int_t)last));
}

/* A real, so that the value reads back as the same double. */
bool pfx_manifest_set_slice_number(pfx_manifest *m, const char *key, double value) {
    json_t *slice = member(m, "slice");
    return json_is_object(slice) && json_object_set_new(slice, key, json_real(value)) == 0;
}

double pfx_manifest_slice_number(const pfx_manifest *m, const char *key, double fallback) {
    json_t *v = json_object_get(member(m, "slice"), key);
    return json_is_number(v) ? json_number_value(v) : fallback;
}

static bool is_render(const pfx_manifest *m) {
    const char *c = json_string_value(member(m, "command"));
    return c && !strcmp(c, "render");
}

/* The slice member of a part: index, count and the whole range, within
 * what render --slice and --frames accept (so that a crafted count cannot
 * make assemble allocate or report without bound). */
static bool slice_of(const pfx_manifest *m, json_int_t *index, json_int_t *count, json_int_t *first,
                     json_int_t *last) {
    return json_unpack(member(m, "slice"), "{s:I, s:I, s:[I, I]}", "index", index, "count", count,
                       "frames", first, last) == 0 &&
           *count >= 1 && *count <= 1000000 && *index >= 0 && *index < *count && *first >= 0 &&
           *first <= *last && *last <= 100000000;
}

/* The settings without the frame range, for comparing slices. */
static json_t *settings_but_frames(const pfx_manifest *m) {
    json_t *s = json_deep_copy(member(m, "settings"));
    json_object_del(s, "frames");
    return s;
}

/* Whether a and b record the same member k (both without it counts). */
static bool same_member(const pfx_manifest *a, const pfx_manifest *b, const char *k) {
    const json_t *x = member(a, k), *y = member(b, k);
    return (!x && !y) || (x && y && json_equal(x, y));
}

/* dst's member k as src records it, or none where src has none. */
static void copy_member(pfx_manifest *dst, const pfx_manifest *src, const char *k) {
    json_t *v = member(src, k);
    if (v)
        json_object_set(dst->root, k, v);
    else
        json_object_del(dst->root, k);
}

void pfx_manifest_keep_preview(pfx_manifest *now, const pfx_manifest *prev) {
    json_t *p = member(prev, "preview");
    json_object_set_new(now->root, "preview", p ? json_deep_copy(p) : json_null());
}

static int by_path(const void *a, const void *b) {
    const char *x = json_string_value(json_object_get(*(json_t *const *)a, "path"));
    const char *y = json_string_value(json_object_get(*(json_t *const *)b, "path"));
    return strcmp(x ? x : "", y ? y : "");
}

pfx_manifest *pfx_manifest_assemble(pfx_manifest *const *parts, const char *const *names, size_t n,
                                    long *first, long *last, pfx_diags *d) {
    json_int_t index, count, f0, f1, c0 = 0, a0 = 0, b0 = 0;
    const char **seen = NULL;
    pfx_manifest *out = NULL;
    json_t *ref = NULL;
    const char *ref_name = NULL; /* the part the others are compared with */
    int errors = d->errors;
    for (size_t k = 0; k < n; k++) {
        if (!slice_of(parts[k], &index, &count, &f0, &f1) || !is_render(parts[k])) {
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                           "'%s' is not the manifest of a render slice", names[k]);
            continue;
        }
        json_t *s = settings_but_frames(parts[k]);
        if (!ref) {
            ref = s;
            ref_name = names[k];
            c0 = count, a0 = f0, b0 = f1;
            seen = calloc((size_t)count, sizeof *seen);
            out = pfx_manifest_create("render");
            if (!seen || !out) {
                pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
                break;
            }
            json_object_set_new(out->root, "settings",
                                json_deep_copy(member(parts[k], "settings")));
            json_object_set(out->root, "inputs", member(parts[k], "inputs"));
            /* the build that made the frames, not the one that gathers them */
            copy_member(out, parts[k], "pfx_version");
            copy_member(out, parts[k], "pfx_results");
        } else {
            bool same = json_equal(ref, s) && count == c0 && f0 == a0 && f1 == b0 &&
                        json_equal(member(parts[k], "inputs"), member(out, "inputs"));
            json_decref(s);
            if (!same) {
                pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                               "'%s' is a slice of another render than '%s' (other inputs, "
                               "settings or slice count)",
                               names[k], ref_name);
                continue;
            }
            if (!same_member(parts[k], out, "pfx_version") ||
                !same_member(parts[k], out, "pfx_results")) {
                pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                               "'%s' was rendered by another build of pfx than '%s' (other "
                               "pfx_version or pfx_results): its frames may differ",
                               names[k], ref_name);
                continue;
            }
        }
        if (seen[index]) {
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                           "slice %lld of %lld is in both '%s' and '%s'", (long long)index,
                           (long long)count, seen[index], names[k]);
            continue;
        }
        seen[index] = names[k];
        merge_outputs(out, parts[k], names[k], d);
    }
    /* The first few missing slices by number, then how many more. */
    json_int_t missing = 0;
    for (json_int_t i = 0; seen && i < c0; i++)
        if (!seen[i] && ++missing <= 10)
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES, "slice %lld of %lld is missing",
                           (long long)i, (long long)c0);
    if (missing > 10)
        pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES, "%lld more slices of %lld are missing",
                       (long long)(missing - 10), (long long)c0);
    free(seen);
    json_decref(ref);
    if (!out || d->errors > errors) {
        pfx_manifest_destroy(out);
        return NULL;
    }
    /* Sorted outputs, and the frames of the whole render. */
    json_t *outputs = member(out, "outputs");
    size_t count_out = json_array_size(outputs);
    json_t **items = malloc((count_out + 1) * sizeof *items);
    if (!items) {
        pfx_manifest_destroy(out);
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        return NULL;
    }
    for (size_t i = 0; i < count_out; i++)
        items[i] = json_incref(json_array_get(outputs, i));
    qsort(items, count_out, sizeof *items, by_path);
    json_array_clear(outputs);
    index_drop(out);
    for (size_t i = 0; i < count_out; i++)
        json_array_append_new(outputs, items[i]);
    free(items);
    *first = (long)a0;
    *last = (long)b0;
    pfx_manifest_set_range(out, "frames", *first, *last);
    pfx_manifest_key(out);
    return out;
}

/* name for a message: control bytes as '?', so that a crafted name cannot
 * rewrite the terminal; cut short after 80 bytes. */
static const char *printable(const char *name, char buf[96]) {
    size_t i = 0;
    for (; name[i] && i < 80; i++)
        buf[i] = (unsigned char)name[i] < 0x20 || name[i] == 0x7f ? '?' : name[i];
    strcpy(buf + i, name[i] ? "..." : "");
    return buf;
}

/* Appends src's outputs to dst. A name that is not a plain file name (a
 * '/', a leading '.', a control byte: a slice's directory is input, and
 * "../x" would make assemble write outside its directory), a missing or
 * malformed SHA-256, or a name already there is an error. */
static bool merge_outputs(pfx_manifest *dst, const pfx_manifest *src, const char *src_name,
                          pfx_diags *d) {
    for (size_t i = 0; i < pfx_manifest_output_count(src); i++) {
        const char *sha, *name = pfx_manifest_output(src, i, &sha);
        char shown[96];
        if (!plain_name(name)) {
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                           "'%s' lists the output '%s', which is not a plain file name in its "
                           "directory",
                           src_name, name ? printable(name, shown) : "(not a string)");
            return false;
        }
        if (!is_sha256(sha)) {
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES,
                           "'%s' records no SHA-256 for the output '%s'", src_name,
                           printable(name, shown));
            return false;
        }
        json_t *old = find_output(dst, name);
        if (old) {
            const char *old_sha = json_string_value(json_object_get(old, "sha256"));
            pfx_diag_error(d, PFX_RULE_INCONSISTENT_SLICES, "'%s' is in two slices%s", name,
                           old_sha && strcmp(old_sha, sha) ? ", with different contents" : "");
            return false;
        }
        append_output(dst, name, sha);
    }
    return true;
}
