/* libFuzzer target: src/jobs from crafted slice folders, the path of
 * `pfx assemble` and of render's manifest checks. Each input is up to four
 * files cut at the line "#--": the manifests of slices 0 and 1 of 'fire'
 * and the frames fire_0000.png (in slice 0) and fire_0001.png (in slice
 * 1); "$SHA0" and "$SHA1" in a manifest become the frames' SHA-256, so the
 * fuzzer gets past the hash check to the gathering, the atlas and the
 * preview. Then the assembled manifest is read back, checked for up to
 * date, written as a depfile, and one slice manifest is taken as the
 * previous run of the other (stale outputs removed from the slice folder).
 * A crash, a sanitizer report, a leak, a hang or a file outside this
 * process's own folder is a finding. */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/sha256.h"
#include "jobs/assemble.h"
#include "jobs/depfile.h"
#include "jobs/manifest.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char top[64];
static const char *const sub[] = {"s0", "s1", "out"};

/* Empties top/<name> (files only: pfx makes no folders there). */
static void empty(const char *name) {
    char dir[128], path[512];
    snprintf(dir, sizeof dir, "%s/%s", top, name);
    DIR *dh = opendir(dir);
    struct dirent *e;
    while (dh && (e = readdir(dh)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            unlink(path);
        }
    if (dh)
        closedir(dh);
}

static void cleanup(void) {
    for (size_t i = 0; i < 3; i++) {
        char dir[128];
        empty(sub[i]);
        snprintf(dir, sizeof dir, "%s/%s", top, sub[i]);
        rmdir(dir);
    }
    rmdir(top);
}

static bool setup(void) {
    snprintf(top, sizeof top, "/tmp/pfx-fuzz-jobs-XXXXXX");
    if (!mkdtemp(top))
        return false;
    for (size_t i = 0; i < 3; i++) {
        char dir[128];
        snprintf(dir, sizeof dir, "%s/%s", top, sub[i]);
        if (mkdir(dir, 0700) != 0)
            return false;
    }
    atexit(cleanup);
    return true;
}

static void put(const char *name, const void *bytes, size_t n) {
    char path[256];
    snprintf(path, sizeof path, "%s/%s", top, name);
    FILE *f = fopen(path, "wb");
    if (f) {
        fwrite(bytes, 1, n, f);
        fclose(f);
    }
}

/* The first n bytes equal to pat in [at, end), or NULL (memmem is not
 * POSIX). */
static const uint8_t *find(const uint8_t *at, const uint8_t *end, const char *pat, size_t n) {
    for (; (size_t)(end - at) >= n; at++)
        if (!memcmp(at, pat, n))
            return at;
    return NULL;
}

/* text[0..n) with every "$SHAk" replaced by hex[k], as a new string. */
static char *with_hashes(const uint8_t *text, size_t n, char hex[2][PFX_SHA256_HEX]) {
    char *out = malloc(n * 64 / 5 + 64);
    size_t o = 0;
    if (!out)
        return NULL;
    for (size_t i = 0; i < n;) {
        if (n - i >= 5 && !memcmp(text + i, "$SHA", 4) &&
            (text[i + 4] == '0' || text[i + 4] == '1')) {
            memcpy(out + o, hex[text[i + 4] - '0'], 64);
            o += 64;
            i += 5;
        } else {
            out[o++] = (char)text[i++];
        }
    }
    out[o] = 0;
    return out;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static bool ready;
    if (!ready && !(ready = setup()))
        return 0;
    for (size_t i = 0; i < 3; i++)
        empty(sub[i]);
    /* The four parts. */
    const uint8_t *part[4] = {0};
    size_t len[4] = {0}, k = 0;
    const uint8_t *at = data, *end = data + size;
    static const char cut[] = "\n#--\n";
    while (k < 4) {
        const uint8_t *next = find(at, end, cut, sizeof cut - 1);
        part[k] = at;
        len[k] = (size_t)((next ? next : end) - at);
        k++;
        if (!next)
            break;
        at = next + sizeof cut - 1;
    }
    char hex[2][PFX_SHA256_HEX];
    pfx_sha256_bytes(part[2] ? part[2] : data, len[2], hex[0]);
    pfx_sha256_bytes(part[3] ? part[3] : data, len[3], hex[1]);
    put("s0/fire_0000.png", part[2] ? part[2] : data, len[2]);
    put("s1/fire_0001.png", part[3] ? part[3] : data, len[3]);
    static const char *const names[] = {"s0/fire.slice-0000-of-0002.manifest.json",
                                        "s1/fire.slice-0001-of-0002.manifest.json"};
    for (int m = 0; m < 2; m++) {
        char *text = part[m] ? with_hashes(part[m], len[m], hex) : NULL;
        if (text)
            put(names[m], text, strlen(text));
        free(text);
    }
    /* assemble, with the atlas and the preview as a render would make them. */
    char s0[128], s1[128], out[128], path[256];
    snprintf(s0, sizeof s0, "%s/s0", top);
    snprintf(s1, sizeof s1, "%s/s1", top);
    snprintf(out, sizeof out, "%s/out", top);
    snprintf(path, sizeof path, "%s/out/fire.webp", top);
    const char *dirs[] = {s0, s1};
    pfx_atlas_layout atlas = {.padding = 2, .extrude = 1};
    pfx_assemble_options opt = {.atlas = &atlas, .preview = path};
    pfx_assemble_report r;
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    pfx_assemble(dirs, 2, out, &opt, &r, &d);
    /* The result (or a slice's manifest) as render's previous run. */
    snprintf(path, sizeof path, "%s/out/fire.manifest.json", top);
    pfx_manifest *m = pfx_manifest_read(path);
    if (!m) {
        snprintf(path, sizeof path, "%s/%s", top, names[0]);
        m = pfx_manifest_read(path);
    }
    if (m) {
        pfx_manifest_up_to_date(m, pfx_manifest_recorded_key(m), out);
        snprintf(path, sizeof path, "%s/out/fire.d", top);
        pfx_depfile_write(path, "fire.manifest.json", m, &d);
        snprintf(path, sizeof path, "%s/%s", top, names[1]);
        pfx_manifest *other = pfx_manifest_read(path);
        if (other)
            pfx_manifest_remove_stale(m, other, s0, &d);
        pfx_manifest_destroy(other);
    }
    pfx_manifest_destroy(m);
    /* PFX_FUZZ_VERBOSE=1 shows what pfx said, to read a finding. */
    static FILE *sink;
    if (!sink)
        sink = getenv("PFX_FUZZ_VERBOSE") ? stderr : fopen("/dev/null", "w");
    if (sink)
        pfx_diags_print(&d, sink, false);
    pfx_diags_free(&d);
    return 0;
}
