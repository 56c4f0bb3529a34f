/* Unit tests of src/output/png_write.c: exact round trips, byte-identical
 * output, no file (final or temporary) left behind by any failure, the
 * reader's conversions, and the frame queue's order and first-error
 * reporting (output/frame_queue.c, whose encoders convert float frames).
 * Everything happens in a fresh directory under $TMPDIR, removed at the end. */
#include "output/frame_queue.h"
#include "output/png_write.h"
#include "test.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <png.h>
#include <signal.h>
#include <stdint.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* The writer reports into a diagnostics list; the tests read its first
 * message as err ("" when it reported nothing). */
static void first_message(pfx_diags *d, char *err) {
    snprintf(err, 512, "%s", d->count ? d->items[0].message : "");
    pfx_diags_free(d);
}

static bool write_png(const char *path, const uint8_t *rgba, int w, int h, char *err) {
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    bool ok = pfx_png_write(path, rgba, w, h, &d);
    first_message(&d, err);
    return ok;
}

static bool finish_queue(pfx_frame_queue *q, char *err) {
    pfx_diags d;
    pfx_diags_init_runtime(&d);
    bool ok = pfx_frame_queue_finish(q, &d);
    first_message(&d, err);
    return ok;
}

static char test_dir[256];

static void path_in(char *out, size_t size, const char *name) {
    snprintf(out, size, "%s/%s", test_dir, name);
}

/* A deterministic image with a transparent background whose colour bytes are
 * not zero, so a writer that drops or premultiplies them is caught. */
static uint8_t *make_image(int width, int height, uint32_t seed) {
    uint8_t *rgba = malloc((size_t)width * (size_t)height * 4);
    uint32_t x = seed * 2654435761u + 1u;
    for (size_t i = 0; i < (size_t)width * (size_t)height; i++) {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        uint8_t *p = rgba + i * 4;
        p[0] = (uint8_t)x;
        p[1] = (uint8_t)(x >> 8);
        p[2] = (uint8_t)(x >> 16);
        /* Mostly alpha 0, some partial, some opaque, like a particle frame. */
        uint8_t pick = (uint8_t)(x >> 24);
        p[3] = pick < 160 ? 0 : pick < 230 ? (uint8_t)(pick * 7) : 255;
    }
    return rgba;
}

static uint8_t *read_file_bytes(const char *path, size_t *size) {
    FILE *f = fopen(path, "rb");
    if (f == NULL)
        return NULL;
    uint8_t *data = NULL;
    size_t used = 0, cap = 0;
    for (;;) {
        if (used == cap) {
            cap = cap ? cap * 2 : 4096;
            data = realloc(data, cap);
        }
        size_t n = fread(data + used, 1, cap - used, f);
        used += n;
        if (n == 0)
            break;
    }
    fclose(f);
    *size = used;
    return data;
}

/* Number of entries in dir other than . and .., listing them if asked. */
static int count_entries(const char *dir, bool show) {
    DIR *d = opendir(dir);
    if (d == NULL)
        return -1;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        if (show)
            fprintf(stderr, "  found '%s/%s'\n", dir, e->d_name);
        n++;
    }
    closedir(d);
    return n;
}

/* Checks that dir holds exactly `expected` entries: no stray temporary. */
static void check_entries(const char *dir, int expected) {
    int n = count_entries(dir, false);
    CHECK(n == expected);
    if (n != expected)
        count_entries(dir, true);
}

static bool file_exists(const char *path) {
    struct stat st;
    return stat(path, &st) == 0;
}

/* Checks that the PNG at path reads back as the w x h RGBA image want. */
static void check_reads_back(const char *path, const uint8_t *want, int w, int h) {
    int rw = 0, rh = 0;
    uint8_t *back = pfx_png_read(path, &rw, &rh);
    CHECK(back != NULL);
    CHECK(rw == w && rh == h);
    if (back != NULL && rw == w && rh == h)
        CHECK(memcmp(back, want, (size_t)w * h * 4) == 0);
    free(back);
}

/* Removes the regular files in dir, then dir itself. */
static void remove_dir(const char *dir) {
    DIR *d = opendir(dir);
    if (d == NULL)
        return;
    struct dirent *e;
    char path[512];
    while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        unlink(path);
    }
    closedir(d);
    rmdir(dir);
}

static void test_round_trip(void) {
    char path[512];
    path_in(path, sizeof path, "round.png");
    int w = 37, h = 23; /* odd sizes catch stride mistakes */
    uint8_t *rgba = make_image(w, h, 1);
    char err[512] = "";
    CHECK(write_png(path, rgba, w, h, err));
    CHECK(err[0] == '\0');
    check_reads_back(path, rgba, w, h);
    /* Only the file itself: the temporary was renamed, not copied. */
    check_entries(test_dir, 1);
    free(rgba);
    unlink(path);
}

/* The encoder's corner cases: one pixel, one byte value everywhere (a single
 * literal symbol, so the Huffman code needs a second one), all zero (runs
 * only), runs longer than deflate's 258 and runs that stop just short of a
 * word boundary. Each must read back exactly. */
static void test_round_trip_edges(void) {
    const int sizes[][2] = {{1, 1}, {1, 9}, {9, 1}, {3, 5}, {65, 3}, {300, 2}};
    char path[512], err[512];
    path_in(path, sizeof path, "edge.png");
    for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++) {
        int w = sizes[k][0], h = sizes[k][1];
        size_t n = (size_t)w * (size_t)h * 4;
        uint8_t *rgba = malloc(n);
        for (int mode = 0; mode < 4; mode++) {
            for (size_t i = 0; i < n; i++) {
                uint8_t v = mode == 0 ? 0 : mode == 1 ? 255 : (uint8_t)(i / 7);
                rgba[i] = mode == 3 ? (uint8_t)((i % 11) < 9 ? 0 : i) : v;
            }
            err[0] = '\0';
            CHECK(write_png(path, rgba, w, h, err));
            check_reads_back(path, rgba, w, h);
        }
        free(rgba);
    }
    unlink(path);
}

/* Chunk types of a PNG file in order, as 4-letter words, into types[]
 * (at most `most`); the count, or -1 when the file cannot be read. */
static int chunk_types(const char *path, char types[][5], int most) {
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    uint8_t head[8];
    int n = 0;
    if (fread(head, 1, 8, f) != 8) { /* the signature */
        fclose(f);
        return -1;
    }
    while (n < most && fread(head, 1, 8, f) == 8) {
        long len = (long)head[0] << 24 | head[1] << 16 | head[2] << 8 | head[3];
        memcpy(types[n], head + 4, 4);
        types[n++][4] = '\0';
        if (fseek(f, len + 4, SEEK_CUR) != 0) /* data and CRC */
            break;
    }
    fclose(f);
    return n;
}

/* Noise does not compress: a 2.1 MB image needs an IDAT stream longer than
 * one chunk holds (1 MiB), so it is split, and libpng reads it back whole. */
static void test_round_trip_split_idat(void) {
    char path[512], err[512] = "";
    path_in(path, sizeof path, "noise.png");
    int w = 733, h = 719;
    size_t n = (size_t)w * (size_t)h * 4;
    uint8_t *rgba = malloc(n);
    CHECK(rgba != NULL);
    if (!rgba)
        return;
    uint32_t x = 12345;
    for (size_t i = 0; i < n; i++) {
        x ^= x << 13, x ^= x >> 17, x ^= x << 5; /* xorshift32 */
        rgba[i] = (uint8_t)(x >> 24);
    }
    CHECK(write_png(path, rgba, w, h, err));
    char types[16][5];
    int chunks = chunk_types(path, types, 16);
    CHECK(chunks == 5); /* IHDR IDAT IDAT IDAT IEND: 2.1 MB in 1 MiB pieces */
    if (chunks == 5)
        CHECK(!strcmp(types[0], "IHDR") && !strcmp(types[1], "IDAT") && !strcmp(types[3], "IDAT") &&
              !strcmp(types[4], "IEND"));
    check_reads_back(path, rgba, w, h);
    free(rgba);
    unlink(path);
}

static void test_deterministic_bytes(void) {
    char a[512], b[512];
    path_in(a, sizeof a, "same_a.png");
    path_in(b, sizeof b, "same_b.png");
    int w = 64, h = 40;
    uint8_t *rgba = make_image(w, h, 2);
    char err[512];
    CHECK(write_png(a, rgba, w, h, err));
    CHECK(write_png(b, rgba, w, h, err));
    size_t na = 0, nb = 0;
    uint8_t *da = read_file_bytes(a, &na);
    uint8_t *db = read_file_bytes(b, &nb);
    CHECK(da != NULL && db != NULL && na > 0);
    CHECK(na == nb);
    if (da != NULL && db != NULL && na == nb)
        CHECK(memcmp(da, db, na) == 0);
    /* Overwriting an existing file replaces it with the same bytes. */
    CHECK(write_png(a, rgba, w, h, err));
    size_t nc = 0;
    uint8_t *dc = read_file_bytes(a, &nc);
    CHECK(dc != NULL && nc == na);
    if (dc != NULL && da != NULL && nc == na)
        CHECK(memcmp(dc, da, na) == 0);
    free(da);
    free(db);
    free(dc);
    free(rgba);
    unlink(a);
    unlink(b);
}

/* A failed write returns false, names the path, and leaves dir as it was. */
static void check_write_fails(const char *path, const char *dir, int entries_before) {
    uint8_t *rgba = make_image(16, 16, 3);
    char err[512] = "";
    CHECK(!write_png(path, rgba, 16, 16, err));
    CHECK(strstr(err, path) != NULL);
    if (strstr(err, path) == NULL)
        fprintf(stderr, "  message was: %s\n", err);
    struct stat st;
    CHECK(stat(path, &st) != 0 || !S_ISREG(st.st_mode));
    check_entries(dir, entries_before);
    free(rgba);
}

static void test_missing_directory(void) {
    char path[512];
    path_in(path, sizeof path, "no/such/dir/a.png");
    check_write_fails(path, test_dir, 0);
    char err[512] = "";
    uint8_t px[4] = {1, 2, 3, 4};
    CHECK(!write_png(path, px, 1, 1, err));
    CHECK(strstr(err, "No such file or directory") != NULL);
}

/* The writes into read-only directory dir (path inside it) fail cleanly. */
static void read_only_checks(const char *path, const char *dir) {
    check_write_fails(path, dir, 0);
    char err[512] = "";
    uint8_t px[4] = {1, 2, 3, 4};
    CHECK(!write_png(path, px, 1, 1, err));
    CHECK(strstr(err, "Permission denied") != NULL);
}

/* Directory permissions do not stop root, and the tests often run as root
 * (containers, CI): there the checks run in a child that drops to the user
 * nobody (65534), so they are made everywhere rather than skipped. */
static void test_read_only_directory(void) {
    char dir[512], path[600];
    path_in(dir, sizeof dir, "readonly");
    CHECK(mkdir(dir, 0700) == 0);
    snprintf(path, sizeof path, "%s/a.png", dir);
    if (geteuid() != 0) {
        CHECK(chmod(dir, 0500) == 0);
        read_only_checks(path, dir);
    } else {
        /* nobody must reach dir through the mkdtemp directory (0700). */
        CHECK(chmod(test_dir, 0711) == 0);
        CHECK(chmod(dir, 0555) == 0);
        fflush(stderr);
        pid_t pid = fork();
        if (pid == 0) {
            if (setgid(65534) != 0 || setuid(65534) != 0 || geteuid() == 0) {
                fprintf(stderr, "  cannot become nobody: %s\n", strerror(errno));
                _exit(2);
            }
            read_only_checks(path, dir);
            fflush(stderr);
            _exit(test_failures == 0 ? 0 : 1); /* _exit: no leak check of the copy */
        }
        int st = 0;
        CHECK(pid > 0 && waitpid(pid, &st, 0) == pid);
        CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 0);
        chmod(test_dir, 0700);
    }
    chmod(dir, 0700);
    rmdir(dir);
}

/* rename() onto a directory fails after the temporary is complete, so this
 * checks the temporary is removed on the last possible failure. */
static void test_rename_failure_cleans_up(void) {
    char dir[512];
    path_in(dir, sizeof dir, "is_a_dir.png");
    CHECK(mkdir(dir, 0700) == 0);
    check_write_fails(dir, test_dir, 1);
    rmdir(dir);
}

/* A file size limit makes fwrite fail in the middle of encoding, which
 * exercises the longjmp out of libpng and the removal of a partial file. */
static void test_write_error_mid_file(void) {
    struct rlimit old;
    CHECK(getrlimit(RLIMIT_FSIZE, &old) == 0);
    void (*old_handler)(int) = signal(SIGXFSZ, SIG_IGN);
    struct rlimit small = old;
    small.rlim_cur = 10000;
    CHECK(setrlimit(RLIMIT_FSIZE, &small) == 0);

    char path[512];
    path_in(path, sizeof path, "too_big.png");
    int w = 256, h = 256; /* random pixels: well over 10000 bytes compressed */
    uint8_t *rgba = make_image(w, h, 4);
    for (size_t i = 0; i < (size_t)w * h; i++)
        rgba[i * 4 + 3] = rgba[i * 4];
    char err[512] = "";
    bool ok = write_png(path, rgba, w, h, err);

    CHECK(setrlimit(RLIMIT_FSIZE, &old) == 0);
    signal(SIGXFSZ, old_handler);
    CHECK(!ok);
    CHECK(strstr(err, path) != NULL);
    CHECK(strstr(err, "File too large") != NULL);
    if (strstr(err, "File too large") == NULL)
        fprintf(stderr, "  message was: %s\n", err);
    CHECK(!file_exists(path));
    check_entries(test_dir, 0);
    free(rgba);
}

static void test_invalid_size(void) {
    char path[512], err[512] = "";
    path_in(path, sizeof path, "empty.png");
    uint8_t px[4] = {0};
    CHECK(!write_png(path, px, 0, 5, err));
    CHECK(strstr(err, path) != NULL);
    CHECK(!file_exists(path));
    check_entries(test_dir, 0);
}

static void test_read_rejects_bad_files(void) {
    char path[512];
    path_in(path, sizeof path, "missing.png");
    int w = -1, h = -1;
    CHECK(pfx_png_read(path, &w, &h) == NULL);

    path_in(path, sizeof path, "not_a.png");
    FILE *f = fopen(path, "wb");
    fputs("this is not a PNG file, not even close", f);
    fclose(f);
    CHECK(pfx_png_read(path, &w, &h) == NULL);
    unlink(path);

    /* Truncated in the middle of the image data: fails inside
     * png_read_image, after the buffers were allocated. */
    path_in(path, sizeof path, "truncated.png");
    uint8_t *rgba = make_image(64, 64, 5);
    char err[512];
    CHECK(write_png(path, rgba, 64, 64, err));
    size_t n = 0;
    uint8_t *bytes = read_file_bytes(path, &n);
    CHECK(bytes != NULL && n > 200);
    f = fopen(path, "wb");
    fwrite(bytes, 1, n / 2, f);
    fclose(f);
    CHECK(pfx_png_read(path, &w, &h) == NULL);
    unlink(path);
    free(bytes);
    free(rgba);
}

/* Files pfx does not write itself: gray, 16-bit and palette with tRNS must
 * all come back as 8-bit RGBA. */
static void test_read_converts(void) {
    char path[512];
    path_in(path, sizeof path, "convert.png");
    int w = 0, h = 0;

    uint8_t gray[6] = {0, 1, 127, 128, 254, 255};
    png_image img = {
        .version = PNG_IMAGE_VERSION, .width = 3, .height = 2, .format = PNG_FORMAT_GRAY};
    CHECK(png_image_write_to_file(&img, path, 0, gray, 0, NULL));
    uint8_t *back = pfx_png_read(path, &w, &h);
    CHECK(back != NULL && w == 3 && h == 2);
    for (int i = 0; back != NULL && i < 6; i++) {
        CHECK(back[i * 4] == gray[i] && back[i * 4 + 1] == gray[i]);
        CHECK(back[i * 4 + 2] == gray[i] && back[i * 4 + 3] == 255);
    }
    free(back);

    /* 16-bit multiples of 257 scale to 8 bits exactly. */
    uint16_t rgb16[6] = {0, 257 * 10, 257 * 200, 65535, 257 * 1, 257 * 99};
    png_image img16 = {
        .version = PNG_IMAGE_VERSION, .width = 2, .height = 1, .format = PNG_FORMAT_LINEAR_RGB};
    CHECK(png_image_write_to_file(&img16, path, 0, rgb16, 0, NULL));
    back = pfx_png_read(path, &w, &h);
    CHECK(back != NULL && w == 2 && h == 1);
    uint8_t want16[8] = {0, 10, 200, 255, 255, 1, 99, 255};
    if (back != NULL)
        CHECK(memcmp(back, want16, 8) == 0);
    free(back);

    uint8_t map[3 * 4] = {255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 255};
    uint8_t index[4] = {0, 1, 2, 1};
    png_image pal = {.version = PNG_IMAGE_VERSION,
                     .width = 2,
                     .height = 2,
                     .format = PNG_FORMAT_RGBA_COLORMAP,
                     .colormap_entries = 3};
    CHECK(png_image_write_to_file(&pal, path, 0, index, 0, map));
    back = pfx_png_read(path, &w, &h);
    CHECK(back != NULL && w == 2 && h == 2);
    for (int i = 0; back != NULL && i < 4; i++)
        CHECK(memcmp(back + i * 4, map + index[i] * 4, 4) == 0);
    free(back);
    unlink(path);
}

/* Premultiplied output with no exposure, curve or dither: the encoders'
 * conversion gives back byte b from the float b / 255. */
static const pfx_tone exact = {.alpha = PFX_ALPHA_PREMULTIPLIED};

/* Fills a queue frame with the 8-bit image as floats over the whole frame
 * (the box is the frame; rows bottom first, as GL reads them). */
static void fill_frame(pfx_float_image *img, const uint8_t *rgba, int w, int h) {
    img->x0 = img->y0 = 0;
    img->x1 = w;
    img->y1 = h;
    memset(img->clear, 0, sizeof img->clear);
    for (int y = 0; y < h; y++)
        for (int i = 0; i < w * 4; i++)
            img->pixels[(size_t)(h - 1 - y) * w * 4 + i] = rgba[(size_t)y * w * 4 + i] / 255.0f;
}

/* Every frame arrives whole at its own path, with one encoder or several
 * (frames then finish in any order; the files are the same). */
/* held: the encoders take nothing until finish, so the caller encodes
 * every frame it needs a slot back from (all but the last 2 x encoders). */
static void queue_frames(int encoders, bool held) {
    enum { frames = 7, w = 48, h = 32 };
    pfx_frame_queue *q = pfx_frame_queue_create(w, h, encoders, PFX_FRAME_PNG, &exact);
    CHECK(q != NULL);
    if (q == NULL)
        return;
    pfx_frame_queue_hold_encoders(q, held);
    uint8_t *sent[frames];
    char path[frames][512];
    for (int i = 0; i < frames; i++) {
        char name[32];
        snprintf(name, sizeof name, "frame_%d.png", i);
        path_in(path[i], sizeof path[i], name);
        sent[i] = make_image(w, h, 100 + (uint32_t)i);
        fill_frame(pfx_frame_queue_buffer(q), sent[i], w, h);
        pfx_frame_queue_submit(q, path[i]);
    }
    CHECK(!pfx_frame_queue_failed(q));
    char err[512] = "";
    CHECK(finish_queue(q, err));
    CHECK(err[0] == '\0');
    for (int i = 0; i < frames; i++) {
        check_reads_back(path[i], sent[i], w, h);
        free(sent[i]);
        unlink(path[i]);
    }
    check_entries(test_dir, 0);
}

static void test_queue_order(void) {
    queue_frames(1, false);
    queue_frames(3, false);
    queue_frames(1, true);
    queue_frames(3, true);
}

/* The first error is the one reported, and frames after it are dropped
 * (with one encoder, which takes frames strictly one after another). held:
 * the caller encodes the first two frames and meets the error; the encoder,
 * let go at finish, drops the other two. */
static void queue_first_error(bool held) {
    enum { w = 8, h = 8 };
    char good[512], bad1[512], bad2[512], after[512];
    path_in(good, sizeof good, "q_good.png");
    path_in(bad1, sizeof bad1, "missing_dir/q_bad1.png");
    path_in(bad2, sizeof bad2, "missing_dir/q_bad2.png");
    path_in(after, sizeof after, "q_after.png");
    const char *paths[4] = {good, bad1, bad2, after};
    pfx_frame_queue *q = pfx_frame_queue_create(w, h, 1, PFX_FRAME_PNG, &exact);
    CHECK(q != NULL);
    if (q == NULL)
        return;
    pfx_frame_queue_hold_encoders(q, held);
    for (int i = 0; i < 4; i++) {
        pfx_float_image *img = pfx_frame_queue_buffer(q);
        img->x0 = img->y0 = img->x1 = img->y1 = 0; /* background alone */
        for (int c = 0; c < 4; c++)
            img->clear[c] = i / 4.0f;
        pfx_frame_queue_submit(q, paths[i]);
    }
    char err[512] = "";
    CHECK(!finish_queue(q, err));
    CHECK(strstr(err, bad1) != NULL);
    if (strstr(err, bad1) == NULL)
        fprintf(stderr, "  message was: %s\n", err);
    CHECK(file_exists(good));
    CHECK(!file_exists(after));
    unlink(good);
    check_entries(test_dir, 0);
}

static void test_queue_first_error(void) {
    queue_first_error(false);
    queue_first_error(true);
}

/* The encoders give way to drawing: each thread's nice value is the
 * process's plus 10 (Linux keeps one per thread; /proc/self/task lists
 * them), while this thread keeps its own. */
static int threads_at_nice(int nice) {
    int count = 0;
    DIR *dir = opendir("/proc/self/task");
    struct dirent *ent;
    while (dir && (ent = readdir(dir)) != NULL) {
        char path[300], buf[1024];
        snprintf(path, sizeof path, "/proc/self/task/%s/stat", ent->d_name);
        FILE *f = ent->d_name[0] != '.' ? fopen(path, "r") : NULL;
        size_t n = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
        if (f)
            fclose(f);
        buf[n] = '\0';
        /* After the command's closing parenthesis: state is field 3, nice 19. */
        const char *p = strrchr(buf, ')');
        for (int field = 2; p && *p && field < 19; p++)
            if (*p == ' ' && ++field == 19)
                count += atoi(p + 1) == nice;
    }
    if (dir)
        closedir(dir);
    return count;
}

static void test_queue_encoders_give_way(void) {
#if defined(__linux__)
    errno = 0;
    const int base = getpriority(PRIO_PROCESS, 0);
    if (errno != 0 || base > 9) {
        fprintf(stderr, "  skipped: this process runs at nice %d\n", base);
        return;
    }
    pfx_frame_queue *q = pfx_frame_queue_create(8, 8, 3, PFX_FRAME_PNG, &exact);
    CHECK(q != NULL);
    if (q == NULL)
        return;
    /* The encoders lower theirs as they start: wait for them (2 s at most). */
    int lowered = 0;
    for (int tries = 0; tries < 200 && (lowered = threads_at_nice(base + 10)) < 3; tries++)
        nanosleep(&(struct timespec){0, 10000000}, NULL);
    CHECK(lowered == 3);
    CHECK(getpriority(PRIO_PROCESS, 0) == base);
    CHECK(pfx_frame_queue_finish(q, NULL));
#endif
}

/* Finishing with nothing submitted, or with a buffer taken but never
 * submitted, succeeds and frees everything. */
static void test_queue_empty(void) {
    pfx_frame_queue *q = pfx_frame_queue_create(4, 4, 2, PFX_FRAME_PNG, &exact);
    CHECK(q != NULL);
    CHECK(pfx_frame_queue_finish(q, NULL));
    q = pfx_frame_queue_create(4, 4, 2, PFX_FRAME_EXR, &exact);
    CHECK(q != NULL);
    CHECK(pfx_frame_queue_buffer(q) != NULL);
    CHECK(pfx_frame_queue_finish(q, NULL));
    CHECK(pfx_frame_queue_create(0, 4, 1, PFX_FRAME_PNG, &exact) == NULL);
}

/* The encoders convert as the renderer's own conversion does: a frame with
 * a small drawn box over a coloured background, exposure, a tone curve and
 * dither, written by three encoders, reads back as the bytes
 * pfx_float_image_to_rgba8 gives on this thread. The background outside
 * the box must come out as the background's bytes. */
static void test_queue_converts(void) {
    enum { w = 40, h = 24, frames = 5 };
    const pfx_tone tone = {
        .exposure = 0.5, .tonemap = PFX_TONEMAP_ACES, .alpha = PFX_ALPHA_STRAIGHT, .dither = true};
    pfx_frame_queue *q = pfx_frame_queue_create(w, h, 3, PFX_FRAME_PNG, &tone);
    CHECK(q != NULL);
    if (q == NULL)
        return;
    float box[10 * 6 * 4];
    uint8_t *want[frames];
    char path[frames][512];
    for (int i = 0; i < frames; i++) {
        for (int k = 0; k < 10 * 6 * 4; k++)
            box[k] = (float)((k * 7 + i * 13) % 40) / 16.0f; /* 0 to 2.4: over 1 too */
        pfx_float_image img = {.width = w,
                               .height = h,
                               .x0 = 5 + i,
                               .y0 = 3,
                               .x1 = 15 + i,
                               .y1 = 9,
                               .pixels = box,
                               .clear = {0.1f, 0.05f, 0.2f, 0.5f}};
        want[i] = malloc((size_t)w * h * 4);
        pfx_float_image_to_rgba8(&img, &tone, want[i]);
        pfx_float_image *slot = pfx_frame_queue_buffer(q);
        float *pixels = slot->pixels;
        memcpy(pixels, box, sizeof box);
        *slot = img;
        slot->pixels = pixels;
        char name[32];
        snprintf(name, sizeof name, "conv_%d.png", i);
        path_in(path[i], sizeof path[i], name);
        pfx_frame_queue_submit(q, path[i]);
    }
    char err[512] = "";
    CHECK(finish_queue(q, err));
    for (int i = 0; i < frames; i++) {
        int rw = 0, rh = 0;
        uint8_t *back = pfx_png_read(path[i], &rw, &rh);
        CHECK(back != NULL && rw == w && rh == h);
        if (back != NULL && rw == w && rh == h) {
            CHECK(memcmp(back, want[i], (size_t)w * h * 4) == 0);
            CHECK(memcmp(back, want[i] + 4 * (w * h - 1), 4) == 0); /* a corner: background */
        }
        free(back);
        free(want[i]);
        unlink(path[i]);
    }
    check_entries(test_dir, 0);
}

/* ---- The float-to-byte conversion against its formula ----
 * render/convert.c converts eight pixels at a time in vector lanes; its
 * contract (the comment at its top) is restated here one pixel at a time,
 * plainly, and the two must give the same bytes on values of every kind:
 * zero and -0, NaN and infinities, negatives, above 1, random bit patterns,
 * pixels equal to the background, boxes of every width (so runs end at any
 * lane), every tone curve, both alpha modes, dither on and off. */
static float spec_curve(const pfx_tone *t, float x) {
    if (t->tonemap == PFX_TONEMAP_REINHARD)
        return x > 0 ? (x < INFINITY ? x / (1 + x) : 1) : 0;
    if (t->tonemap == PFX_TONEMAP_ACES) {
        if (!(x > 0))
            return 0;
        float y = x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f);
        return y < 1 ? y : 1;
    }
    return x;
}

static int spec_byte(float x) {
    if (!(x > 0))
        return 0;
    if (x >= 1)
        return 255;
    float y = 255.0f * x;
    int t = (int)y;
    return y - (float)t >= 0.5f ? t + 1 : t; /* lround(255 x): half away from zero */
}

static float spec_dither(int x, int y, int c) {
    uint32_t h = (uint32_t)x * 0x8da6b343u ^ (uint32_t)y * 0xd8163841u ^ (uint32_t)c * 0xcb1ab31fu;
    h ^= h >> 15;
    h *= 0x2c1b3c6du;
    h ^= h >> 12;
    h *= 0x297a2d39u;
    h ^= h >> 15;
    return ((float)(h >> 8) / 16777216.0f - 0.5f) / 255.0f;
}

static void spec_pixel(const pfx_tone *t, const float src[4], const float clear[4], int x, int y,
                       bool background, uint8_t out[4]) {
    memset(out, 0, 4);
    uint32_t bits[4];
    memcpy(bits, src, sizeof bits);
    if ((bits[0] | bits[1] | bits[2] | bits[3]) == 0)
        return;
    const bool plain = t->exposure == 0 && t->tonemap == PFX_TONEMAP_NONE && t->preserve_hue == 0;
    float p[4] = {src[0], src[1], src[2], src[3]}, g[3];
    for (int c = 0; c < 3 && !plain; c++) {
        g[c] = p[c] * (float)exp2(t->exposure);
        p[c] = spec_curve(t, g[c]);
    }
    if (!plain && t->preserve_hue > 0) {
        /* the brightest channel, a NaN giving way to the other operand */
        float m = (g[1] > g[0] || g[0] != g[0]) ? g[1] : g[0];
        m = (g[2] > m || m != m) ? g[2] : m;
        float cm = spec_curve(t, m);
        cm = cm < 1 ? cm : 1;
        const float s = cm / (m > 0 ? m : 1), k = (float)t->preserve_hue;
        for (int c = 0; c < 3 && m > 0 && m < INFINITY; c++) {
            const float q = p[c] < 1 ? p[c] : 1;
            p[c] = q + k * (g[c] * s - q);
        }
    }
    if (t->alpha == PFX_ALPHA_STRAIGHT) {
        float ap = p[3];
        for (int c = 0; c < 3; c++)
            ap = (p[c] > ap || ap != ap) ? p[c] : ap; /* max, NaN giving way */
        ap = ap > 1 ? 1 : ap;
        if (!(ap > 0))
            return;
        for (int c = 0; c < 3; c++)
            p[c] /= ap;
        p[3] = ap;
    }
    const bool dither = t->dither && !background && memcmp(src, clear, 16) != 0;
    for (int c = 0; c < 4; c++)
        out[c] = (uint8_t)spec_byte(dither ? p[c] + spec_dither(x, y, c) : p[c]);
}

static float odd_value(uint64_t *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    const uint32_t r = (uint32_t)(*s >> 33);
    switch (r % 11) {
    case 0:
        return 0.0f;
    case 1:
        return -0.0f;
    case 2:
        return NAN;
    case 3:
        return (r & 64) ? INFINITY : -INFINITY;
    case 4:
        return -(float)(r % 1000) / 100.0f;
    case 5:
        return (float)(r % 256) / 255.0f; /* on a byte step */
    case 6:
        return (float)(r % 100000) / 1000.0f; /* up to 100 */
    case 7: {
        float f;
        memcpy(&f, &r, sizeof f); /* any bit pattern */
        return f;
    }
    default:
        return (float)(r % 1000003) / 1000003.0f;
    }
}

static void test_conversion_formula(void) {
    uint64_t seed = 12345;
    long differ = 0, bytes = 0;
    for (int trial = 0; trial < 300; trial++) {
        const int w = 9 + trial % 23, h = 4 + trial % 5;
        const int x0 = trial % 3, x1 = x0 + 1 + (trial * 7) % (w - x0), y0 = trial % 2, y1 = h - 1;
        const int bw = x1 - x0, bh = y1 - y0;
        float *box = malloc(sizeof(float) * 4 * (size_t)(bw * bh));
        float clear[4];
        for (int c = 0; c < 4; c++)
            clear[c] = trial % 3 == 0 ? 0.0f : (float)((trial * 31 + c * 17) % 100) / 100.0f;
        for (int i = 0; i < bw * bh; i++) {
            for (int c = 0; c < 4; c++)
                box[4 * i + c] = odd_value(&seed);
            if (seed % 5 == 0)
                memset(box + 4 * i, 0, 16);
            else if (seed % 7 == 0)
                memcpy(box + 4 * i, clear, 16);
        }
        const pfx_tone tone = {.exposure = trial % 4 == 0 ? 0 : (trial % 9) / 2.0 - 2,
                               .tonemap = (pfx_tonemap)(trial % 3),
                               .preserve_hue = trial % 7 < 3 ? 0 : (trial % 7 - 2) / 4.0,
                               .alpha = trial % 2 ? PFX_ALPHA_PREMULTIPLIED : PFX_ALPHA_STRAIGHT,
                               .dither = trial % 5 != 0};
        pfx_float_image img = {
            .width = w, .height = h, .x0 = x0, .y0 = y0, .x1 = x1, .y1 = y1, .pixels = box};
        memcpy(img.clear, clear, sizeof clear);
        uint8_t *got = malloc((size_t)(4 * w * h));
        pfx_float_image_to_rgba8(&img, &tone, got);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                const int gl_y = h - 1 - y;
                const bool in = x >= x0 && x < x1 && gl_y >= y0 && gl_y < y1;
                const float *src = in ? box + 4 * ((gl_y - y0) * bw + (x - x0)) : clear;
                uint8_t want[4];
                spec_pixel(&tone, src, clear, x, y, !in, want);
                differ += memcmp(want, got + 4 * (y * w + x), 4) != 0;
                bytes += 4;
            }
        free(got);
        free(box);
    }
    fprintf(stderr, "  %ld of %ld pixels differ from the formula\n", differ, bytes / 4);
    CHECK(differ == 0);
}

int main(void) {
    const char *tmp = getenv("TMPDIR");
    snprintf(test_dir, sizeof test_dir, "%s/pfx_test_png_XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (mkdtemp(test_dir) == NULL) {
        fprintf(stderr, "cannot create '%s': %s\n", test_dir, strerror(errno));
        return 1;
    }
    RUN(test_round_trip);
    RUN(test_round_trip_edges);
    RUN(test_round_trip_split_idat);
    RUN(test_deterministic_bytes);
    RUN(test_missing_directory);
    RUN(test_read_only_directory);
    RUN(test_rename_failure_cleans_up);
    RUN(test_write_error_mid_file);
    RUN(test_invalid_size);
    RUN(test_read_rejects_bad_files);
    RUN(test_read_converts);
    RUN(test_queue_order);
    RUN(test_queue_first_error);
    RUN(test_queue_empty);
    RUN(test_queue_encoders_give_way);
    RUN(test_queue_converts);
    RUN(test_conversion_formula);
    remove_dir(test_dir);
    return TEST_EXIT();
}
