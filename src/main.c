/* The pfx command: argv -> options, then the stages in order (load, compile,
 * simulate, render or bake, write), and every failure mapped to an exit
 * status: 0 success, 1 invalid input or I/O failure, 2 usage error. It is the
 * only file that knows every stage, and the only one that exits. */
#include <errno.h>
#include <getopt.h>
#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bench/accuracy.h"
#include "bench/speed.h"
#include "compile/read.h"
#include "compile/schema.h"
#include "jobs/assemble.h"
#include "jobs/atlas_job.h"
#include "jobs/delivery.h"
#include "jobs/estimate.h"
#include "jobs/load.h"
#include "jobs/motion_job.h"
#include "jobs/parallel.h"
#include "jobs/preview.h"
#include "jobs/progress.h"
#include "jobs/render_job.h"
#include "jobs/slice.h"
#include "output/atomic_file.h"
#include "output/bake.h"
#include "output/frame_queue.h"
#include "output/mp4.h"
#include "output/sarif.h"
#include "render/render.h"
#include "render/sprites.h"
#include "sim/schedule.h"
#include "sim/sim.h"

#define EXIT_INVALID 1
#define EXIT_USAGE 2

static const char usage_text[] =
    "usage: pfx validate [--format text|json|sarif] [--werror] [--max-particles N]\n"
    "                  [--max-memory SIZE] FILE...\n"
    "       pfx validate --list-rules\n"
    "       pfx render FILE... -o DIR [-j N] [--keep-going] [--frames A:B] [--size WxH]\n"
    "                  [--fps N] [--seed N] [--max-particles N] [--max-memory SIZE]\n"
    "                  [--renderer R] [--alpha MODE] [--threads N] [--force]\n"
    "                  [--depfile FILE] [--progress json]\n"
    "                  [--atlas[=CxR]] [--padding N] [--extrude N] [--crop]\n"
    "                  [--preview OUT.webp|OUT.mp4] [--format png|exr] [-q]\n"
    "                  [--motion-vectors [--mv-max PIXELS] [--mv-flip-y]]\n"
    "                  [--slice I/N | --slice-env VAR --slice-count N]\n"
    "       pfx bake FILE -o OUT [--format csv|ply|pcache] [--every N] [--frames A:B]\n"
    "                  [--fps N] [--seed N] [--max-particles N] [--max-memory SIZE]\n"
    "                  [--threads N] [--force] [--depfile FILE]\n"
    "       pfx info FILE [--format text|json] [--seed N] [--max-particles N]\n"
    "                  [--max-memory SIZE] [--threads N]\n"
    "       pfx bench [--json] [--renderer R]\n"
    "       pfx bench accuracy -o DIR\n"
    "       pfx assemble DIR... -o OUT [--atlas[=CxR]] [--preview OUT.webp|OUT.mp4]\n"
    "       pfx schema\n"
    "\n"
    "commands:\n"
    "  validate   check effect files like a compiler; exit 1 if any has an error\n"
    "  render     render to DIR/<name>_0000.png, ... (several FILEs: DIR/<name>/...)\n"
    "  bake       write the particle state of every output frame: CSV, PLY or pcache\n"
    "  info       show what the compiled effect holds\n"
    "  bench      measure simulation and rendering speed (or integrator accuracy)\n"
    "  assemble   gather the frames of slices (--slice) into OUT, checking each\n"
    "  schema     print the JSON Schema of the effect format\n"
    "\n"
    "options:\n"
    "  -o, --output PATH       output directory (render, bench accuracy) or file (bake;\n"
    "                          - is standard output)\n"
    "      --frames A:B        only frames A to B inclusive, numbered as in a full render\n"
    "      --size WxH          image size in pixels, overriding image.size\n"
    "      --fps N             output frames per second, overriding fps\n"
    "      --seed N            random seed, overriding seed\n"
    "      --max-particles N   particle budget over all emitters (default 1000000)\n"
    "      --max-memory SIZE   refuse a run estimated to need more (K, M, G, T;\n"
    "                          default half of physical memory)\n"
    "      --every N           bake every Nth frame (default 1)\n"
    "      --format FMT        diagnostics as 'text' (default) or 'json' lines, or for\n"
    "                          validate one SARIF 2.1.0 log on stdout ('sarif'); for bake,\n"
    "                          the cache: csv, ply or pcache (default: from the extension);\n"
    "                          for render also the frames: png (default) or exr (linear\n"
    "                          half-float RGBA, premultiplied, exposure but no tone curve)\n"
    "      --list-rules        validate: print every diagnostic's rule id, severity, name\n"
    "                          and meaning\n"
    "  -j, --jobs N            render with N threads, each a contiguous part of the frames\n"
    "      --keep-going        render the other FILEs after one fails\n"
    "      --atlas[=CxR]       also pack the frames into <name>_atlas.png, a grid of C x R\n"
    "                          (default: from the frame count), and <name>_atlas.json\n"
    "      --padding N         atlas: pixels around each frame in its cell (default 2)\n"
    "      --extrude N         atlas: of those, how many repeat the frame's edge (default 1)\n"
    "      --crop              atlas: cut every frame to one box around all visible pixels\n"
    "      --preview OUT.webp  also write the frames as a looping animated WebP (lossless)\n"
    "      --preview OUT.mp4   or as an H.264 MP4, through the ffmpeg on the PATH\n"
    "      --motion-vectors    also write <name>_mv_NNNN.png: 16-bit motion to the next\n"
    "                          frame, R right, G up, 0.5 none (with --atlas: a sheet)\n"
    "      --mv-max PIXELS     the displacement that encodes as 0 or 1 (default: the\n"
    "                          largest in the sequence)\n"
    "      --mv-flip-y         motion vectors with G = down (V down, as in Unreal)\n"
    "      --werror            treat warnings in an effect as errors (exit status 1)\n"
    "      --progress json     a JSON line on stderr per frame drawn, and one at the end\n"
    "      --json              bench: the figures as one JSON object\n"
    "      --threads N         simulation threads (default: PFX_THREADS, else the\n"
    "                          machine's cores); the output is the same for any N\n"
    "      --renderer R        how to get OpenGL (render, bench): auto (default: osmesa\n"
    "                          where built, else egl-cpu), osmesa, egl-cpu, egl-gpu\n"
    "      --force             render or bake even when DIR/<name>.manifest.json (or\n"
    "                          OUT.manifest.json) says the outputs are up to date\n"
    "      --depfile FILE      also write FILE: a Make rule naming every input read\n"
    "      --slice I/N         render only slice I (from 0) of N contiguous frame ranges\n"
    "      --slice-env VAR     the slice index from $VAR (SLURM_ARRAY_TASK_ID,\n"
    "                          JOB_COMPLETION_INDEX, ...), with --slice-count N\n"
    "      --slice-count N     the number of slices for --slice-env\n"
    "      --alpha MODE        PNG alpha: straight or premultiplied, overriding\n"
    "                          image.alpha\n"
    "  -q, --quiet             no progress line and no notes\n"
    "  -h, --help              show this help\n"
    "      --version           show the version\n";

typedef struct options {
    const char *output;
    long first, last; /* --frames; last < 0: to the end */
    bool has_frames;
    const char *format; /* --format, as given; NULL: the command's default */
    bool json;          /* diagnostics as JSON lines (validate --format json) */
    bool sarif;         /* validate --format sarif: one SARIF log on stdout */
    bool list_rules;    /* validate --list-rules */
    bool bench_json;    /* bench --json */
    bool quiet;
    long every;
    pfx_renderer_kind renderer; /* --renderer */
    bool has_renderer;
    uint64_t max_memory; /* --max-memory, else half of physical memory */
    bool force;          /* --force: run even when the manifest says up to date */
    const char *depfile; /* --depfile FILE */
    long slice, slices;  /* --slice I/N, or --slice-env and --slice-count; slices 0: none */
    const char *slice_env;
    long slice_count;
    int jobs;                      /* -j N: threads for render's frames; 0 or 1: one */
    bool keep_going;               /* --keep-going: render the other files after a failure */
    bool progress_json;            /* --progress json: a JSON line per frame on stderr */
    bool werror;                   /* --werror: an effect with a warning fails */
    bool atlas;                    /* --atlas[=COLSxROWS] */
    pfx_atlas_layout atlas_layout; /* its grid, --padding, --extrude, --crop */
    const char *preview;           /* --preview out.webp or out.mp4 */
    bool motion_vectors;           /* --motion-vectors */
    double mv_max;                 /* --mv-max PIXELS; 0: the sequence's largest */
    bool mv_flip_y;                /* --mv-flip-y */
    pfx_frame_format frames_as;    /* render --format png|exr */
    pfx_compile_options compile;
} options;

static int usage_error(const char *fmt, const char *arg) {
    fputs("pfx: ", stderr);
    fprintf(stderr, fmt, arg);
    fputs("\nTry 'pfx --help' for more information.\n", stderr);
    return EXIT_USAGE;
}

static bool parse_ulong(const char *s, unsigned long long *out) {
    if (!s || !*s || *s == '-')
        return false;
    char *end;
    errno = 0;
    *out = strtoull(s, &end, 10);
    return errno == 0 && *end == 0;
}

/* Looks up a renderer name; on a bad one prints the usage error, naming
 * `what` (the option or variable) and every kind, and returns false. */
static bool parse_renderer(const char *what, const char *name, pfx_renderer_kind *kind) {
    if (pfx_renderer_kind_parse(name, kind))
        return true;
    char kinds[128] = "";
    for (int k = 0; k < PFX_RENDERER_KIND_COUNT; k++)
        snprintf(kinds + strlen(kinds), sizeof kinds - strlen(kinds), "%s'%s'",
                 k == 0                             ? ""
                 : k == PFX_RENDERER_KIND_COUNT - 1 ? " or "
                                                    : ", ",
                 pfx_renderer_kind_name((pfx_renderer_kind)k));
    fprintf(stderr, "pfx: %s takes %s, got '%s'\n", what, kinds, name);
    fputs("Try 'pfx --help' for more information.\n", stderr);
    return false;
}

/* The renderer for render and bench: --renderer, else PFX_RENDERER, else
 * auto. Returns false (after the usage error) on a bad PFX_RENDERER. */
static bool renderer_kind(const options *o, pfx_renderer_kind *kind) {
    const char *env = getenv("PFX_RENDERER");
    *kind = PFX_RENDERER_AUTO;
    if (o->has_renderer)
        *kind = o->renderer;
    else if (env && *env)
        return parse_renderer("PFX_RENDERER", env, kind);
    return true;
}

/* --frames: N (one frame), A:B, or A: (from A to the end, last = -1). */
static bool parse_frames(const char *arg, options *o) {
    char buf[64];
    unsigned long long a, b = 0;
    if (strlen(arg) >= sizeof buf)
        return false;
    strcpy(buf, arg);
    char *colon = strchr(buf, ':');
    if (colon)
        *colon = 0;
    if (!parse_ulong(buf, &a) || a > 100000000)
        return false;
    bool to_end = colon && colon[1] == 0;
    if (!colon)
        b = a;
    else if (!to_end && (!parse_ulong(colon + 1, &b) || b < a || b > 100000000))
        return false;
    o->first = (long)a;
    o->last = to_end ? -1 : (long)b;
    o->has_frames = true;
    return true;
}

/* --size: WxH, the x in either case. */
static bool parse_size(const char *arg, unsigned *w, unsigned *h, char *extra) {
    return sscanf(arg, "%u%*[xX]%u%c", w, h, extra) == 2;
}

/* The word to blame for an unknown option or a missing value. getopt has
 * permuted argv and, inside a cluster such as "-j4", not yet moved optind
 * past it, so argv[optind - 1] can be another word: a short option is
 * named by optopt, a long one is the element just consumed. */
static const char *option_word(char **argv, int opt) {
    static char word[3];
    if (opt > 0 && opt < 256) {
        word[0] = '-';
        word[1] = (char)opt;
        return word;
    }
    return argv[optind - 1];
}

/* Parses the options after the command; returns -1 on success or the exit
 * status to stop with. Positional arguments are left in argv[optind..]. */
static int parse_options(int argc, char **argv, options *o) {
    enum {
        OPT_FRAMES = 256,
        OPT_SIZE,
        OPT_FPS,
        OPT_SEED,
        OPT_MAX,
        OPT_EVERY,
        OPT_FORMAT,
        OPT_RENDERER,
        OPT_ALPHA,
        OPT_MAX_MEMORY,
        OPT_THREADS,
        OPT_JSON,
        OPT_FORCE,
        OPT_DEPFILE,
        OPT_SLICE,
        OPT_SLICE_ENV,
        OPT_SLICE_COUNT,
        OPT_KEEP_GOING,
        OPT_PROGRESS,
        OPT_WERROR,
        OPT_LIST_RULES,
        OPT_ATLAS,
        OPT_PADDING,
        OPT_EXTRUDE,
        OPT_CROP,
        OPT_PREVIEW,
        OPT_MOTION_VECTORS,
        OPT_MV_MAX,
        OPT_MV_FLIP_Y
    };
    static const struct option longopts[] = {{"output", required_argument, 0, 'o'},
                                             {"frames", required_argument, 0, OPT_FRAMES},
                                             {"size", required_argument, 0, OPT_SIZE},
                                             {"fps", required_argument, 0, OPT_FPS},
                                             {"seed", required_argument, 0, OPT_SEED},
                                             {"max-particles", required_argument, 0, OPT_MAX},
                                             {"every", required_argument, 0, OPT_EVERY},
                                             {"format", required_argument, 0, OPT_FORMAT},
                                             {"renderer", required_argument, 0, OPT_RENDERER},
                                             {"force", no_argument, 0, OPT_FORCE},
                                             {"depfile", required_argument, 0, OPT_DEPFILE},
                                             {"slice", required_argument, 0, OPT_SLICE},
                                             {"slice-env", required_argument, 0, OPT_SLICE_ENV},
                                             {"slice-count", required_argument, 0, OPT_SLICE_COUNT},
                                             {"jobs", required_argument, 0, 'j'},
                                             {"keep-going", no_argument, 0, OPT_KEEP_GOING},
                                             {"progress", required_argument, 0, OPT_PROGRESS},
                                             {"werror", no_argument, 0, OPT_WERROR},
                                             {"list-rules", no_argument, 0, OPT_LIST_RULES},
                                             {"atlas", optional_argument, 0, OPT_ATLAS},
                                             {"padding", required_argument, 0, OPT_PADDING},
                                             {"extrude", required_argument, 0, OPT_EXTRUDE},
                                             {"crop", no_argument, 0, OPT_CROP},
                                             {"preview", required_argument, 0, OPT_PREVIEW},
                                             {"motion-vectors", no_argument, 0, OPT_MOTION_VECTORS},
                                             {"mv-max", required_argument, 0, OPT_MV_MAX},
                                             {"mv-flip-y", no_argument, 0, OPT_MV_FLIP_Y},
                                             {"alpha", required_argument, 0, OPT_ALPHA},
                                             {"max-memory", required_argument, 0, OPT_MAX_MEMORY},
                                             {"threads", required_argument, 0, OPT_THREADS},
                                             {"json", no_argument, 0, OPT_JSON},
                                             {"quiet", no_argument, 0, 'q'},
                                             {"help", no_argument, 0, 'h'},
                                             {0, 0, 0, 0}};
    unsigned long long v;
    memset(o, 0, sizeof *o);
    /* PFX_THREADS, then --threads over it; neither: the machine's cores. */
    const char *threads = getenv("PFX_THREADS");
    if (threads && *threads) {
        if (!parse_ulong(threads, &v) || v < 1 || v > 1024)
            return usage_error("PFX_THREADS takes a number from 1 to 1024, got '%s'", threads);
        o->compile.threads = (int)v;
    }
    o->last = -1;
    o->atlas_layout.padding = 2;
    o->atlas_layout.extrude = 1;
    o->every = 1;
    o->max_memory = pfx_memory_default_bound();
    opterr = 0;
    optind = 2; /* argv[1] is the command */
    int c;
    while ((c = getopt_long(argc, argv, ":o:j:qh", longopts, NULL)) != -1) {
        switch (c) {
        case 'o':
            o->output = optarg;
            break;
        case 'q':
            o->quiet = true;
            break;
        case 'j':
            if (!parse_ulong(optarg, &v) || v < 1 || v > 256)
                return usage_error("-j takes a number of threads from 1 to 256, got '%s'", optarg);
            o->jobs = (int)v;
            break;
        case OPT_KEEP_GOING:
            o->keep_going = true;
            break;
        case OPT_ATLAS: {
            /* --atlas, --atlas=8x4 or --atlas 8x4: a grid word may follow. */
            const char *grid = optarg;
            unsigned c = 0, r = 0;
            char extra;
            if (!grid && optind < argc && parse_size(argv[optind], &c, &r, &extra))
                grid = argv[optind++];
            if (grid &&
                (!parse_size(grid, &c, &r, &extra) || c < 1 || r < 1 || c > 16384 || r > 16384))
                return usage_error("--atlas takes COLSxROWS, such as 8x8, got '%s'", grid);
            o->atlas = true;
            o->atlas_layout.columns = (int)c;
            o->atlas_layout.rows = (int)r;
            break;
        }
        case OPT_PADDING:
        case OPT_EXTRUDE:
            if (!parse_ulong(optarg, &v) || v > 256)
                return usage_error(c == OPT_PADDING
                                       ? "--padding takes pixels from 0 to 256, got '%s'"
                                       : "--extrude takes pixels from 0 to 256, got '%s'",
                                   optarg);
            if (c == OPT_PADDING)
                o->atlas_layout.padding = (int)v;
            else
                o->atlas_layout.extrude = (int)v;
            break;
        case OPT_PREVIEW: {
            size_t n = strlen(optarg);
            if ((n < 6 || strcmp(optarg + n - 5, ".webp")) && !pfx_mp4_path(optarg))
                return usage_error("--preview writes an animated WebP or an MP4: give a path "
                                   "ending in '.webp' or '.mp4', got '%s'",
                                   optarg);
            o->preview = optarg;
            break;
        }
        case OPT_CROP:
            o->atlas_layout.crop = true;
            break;
        case OPT_MOTION_VECTORS:
            o->motion_vectors = true;
            break;
        case OPT_MV_MAX: {
            char *end;
            double px = strtod(optarg, &end);
            if (*end || !(px > 0 && px <= 1e6))
                return usage_error("--mv-max takes pixels in (0, 1000000], got '%s'", optarg);
            o->mv_max = px;
            break;
        }
        case OPT_MV_FLIP_Y:
            o->mv_flip_y = true;
            break;
        case OPT_WERROR:
            o->werror = true;
            break;
        case OPT_LIST_RULES:
            o->list_rules = true;
            break;
        case OPT_PROGRESS:
            if (strcmp(optarg, "json"))
                return usage_error("--progress takes 'json', got '%s'", optarg);
            o->progress_json = true;
            break;
        case 'h':
            fputs(usage_text, stdout);
            return 0;
        case OPT_FRAMES:
            if (!parse_frames(optarg, o))
                return usage_error("--frames takes N, A:B or A: (to the end) with 0 <= A <= B <= "
                                   "100000000, got '%s'",
                                   optarg);
            break;
        case OPT_SIZE: {
            unsigned w, h;
            char extra;
            if (!parse_size(optarg, &w, &h, &extra) || w < 1 || h < 1 || w > 16384 || h > 16384)
                return usage_error("--size takes WxH with each side from 1 to 16384, got '%s'",
                                   optarg);
            if ((unsigned long long)w * h > PFX_MAX_IMAGE_PIXELS)
                return usage_error("--size takes at most 134217728 pixels (the renderer's float "
                                   "framebuffer: 16 bytes a pixel, 2 GiB), got '%s'",
                                   optarg);
            o->compile.width = (int)w;
            o->compile.height = (int)h;
            break;
        }
        case OPT_FPS: {
            char *end;
            double fps = strtod(optarg, &end);
            if (*end || !(fps > 0 && fps <= 1000))
                return usage_error("--fps takes a number in (0, 1000], got '%s'", optarg);
            o->compile.fps = fps;
            break;
        }
        case OPT_SEED:
            if (!parse_ulong(optarg, &v))
                return usage_error("--seed takes a whole number, got '%s'", optarg);
            o->compile.seed = v;
            o->compile.has_seed = true;
            break;
        case OPT_MAX:
            if (!parse_ulong(optarg, &v) || v < 1 || v > 100000000)
                return usage_error("--max-particles takes a number from 1 to 100000000, got '%s'",
                                   optarg);
            o->compile.max_particles = v;
            break;
        case OPT_EVERY:
            if (!parse_ulong(optarg, &v) || v < 1 || v > 1000000)
                return usage_error("--every takes a whole number from 1, got '%s'", optarg);
            o->every = (long)v;
            break;
        case OPT_FORMAT:
            /* Each command reads its own words (validate: text, json, sarif; bake:
             * csv, ply, pcache); see format_of. */
            if (!pfx_frame_format_parse(optarg, &o->frames_as))
                o->format = optarg;
            else if (strcmp(argv[1], "render"))
                return usage_error("--format %s is for render's frames", optarg);
            break;
        case OPT_RENDERER:
            if (!parse_renderer("--renderer", optarg, &o->renderer))
                return EXIT_USAGE;
            o->has_renderer = true;
            break;
        case OPT_ALPHA: {
            int mode = pfx_kind_find(pfx_alpha_mode_names, optarg);
            if (mode < 0)
                return usage_error("--alpha takes 'straight' or 'premultiplied', got '%s'", optarg);
            o->compile.alpha = (pfx_alpha_mode)mode;
            o->compile.has_alpha = true;
            break;
        }
        case OPT_MAX_MEMORY:
            if (!pfx_memory_parse(optarg, &o->max_memory))
                return usage_error("--max-memory takes a size in bytes, or with K, M, G or T "
                                   "after it, got '%s'",
                                   optarg);
            break;
        case OPT_THREADS:
            if (!parse_ulong(optarg, &v) || v < 1 || v > 1024)
                return usage_error("--threads takes a number from 1 to 1024, got '%s'", optarg);
            o->compile.threads = (int)v;
            break;
        case OPT_JSON:
            o->bench_json = true;
            break;
        case OPT_FORCE:
            o->force = true;
            break;
        case OPT_DEPFILE:
            o->depfile = optarg;
            break;
        case OPT_SLICE: {
            long i, n;
            char extra;
            if (sscanf(optarg, "%ld/%ld%c", &i, &n, &extra) != 2 || n < 1 || n > 1000000 || i < 0 ||
                i >= n)
                return usage_error("--slice takes I/N with 0 <= I < N <= 1000000, got '%s'",
                                   optarg);
            o->slice = i;
            o->slices = n;
            break;
        }
        case OPT_SLICE_ENV:
            o->slice_env = optarg;
            break;
        case OPT_SLICE_COUNT:
            if (!parse_ulong(optarg, &v) || v < 1 || v > 1000000)
                return usage_error("--slice-count takes a number from 1 to 1000000, got '%s'",
                                   optarg);
            o->slice_count = (long)v;
            break;
        case ':':
            return usage_error("option '%s' needs a value", option_word(argv, optopt));
        default:
            return usage_error("unknown option '%s'", option_word(argv, optopt));
        }
    }
    /* --slice-env VAR takes the index from the environment now, so that
     * every later step sees one resolved slice. */
    if (o->slice_env) {
        if (!o->slice_count)
            return usage_error("%s", "--slice-env needs --slice-count N");
        o->slices = o->slice_count;
        const char *v = getenv(o->slice_env);
        if (!pfx_slice_index_from_env(o->slice_env, o->slices, &o->slice)) {
            fprintf(stderr,
                    "pfx: --slice-env %s: the variable must hold a slice index from 0 to %ld, "
                    "got '%s'\n",
                    o->slice_env, o->slices - 1, v ? v : "(unset)");
            return EXIT_USAGE;
        }
    } else if (o->slice_count) {
        return usage_error("%s", "--slice-count goes with --slice-env VAR");
    }
    if (o->preview && o->slices)
        return usage_error("%s", "--preview needs every frame: give it to 'pfx assemble' instead "
                                 "of the slices");
    if (o->preview && argc - optind > 1 && strcmp(argv[1], "render") == 0) {
        int files = 0;
        for (int i = optind; i < argc; i++)
            files += argv[i][0] != '-';
        if (files > 1)
            return usage_error("%s", "--preview names one file: give one FILE");
    }
    /* An MP4 preview needs an ffmpeg: say so before anything is rendered. */
    if (o->preview && pfx_mp4_path(o->preview)) {
        char ffmpeg[4096];
        pfx_diags run;
        pfx_diags_init_runtime(&run);
        bool found = pfx_mp4_find_ffmpeg(o->preview, ffmpeg, sizeof ffmpeg, &run);
        pfx_diags_print(&run, stderr, false);
        pfx_diags_free(&run);
        if (!found)
            return EXIT_INVALID;
    }
    if (o->atlas && o->slices)
        return usage_error("%s", "--atlas needs every frame: give it to 'pfx assemble' instead "
                                 "of the slices");
    if ((o->mv_max > 0 || o->mv_flip_y) && !o->motion_vectors)
        return usage_error("%s", "--mv-max and --mv-flip-y go with --motion-vectors");
    if (o->motion_vectors && strcmp(argv[1], "render"))
        return usage_error("%s", "--motion-vectors is for render");
    if (o->frames_as == PFX_FRAME_EXR) {
        /* EXR keeps the float image; what needs 8-bit frames cannot follow. */
        if (o->atlas || o->preview)
            return usage_error("%s cannot go with --format exr: it is built from 8-bit PNG "
                               "frames; render PNG frames for it",
                               o->atlas ? "--atlas" : "--preview");
        if (o->compile.has_alpha && o->compile.alpha == PFX_ALPHA_STRAIGHT)
            return usage_error("%s", "--alpha straight cannot go with --format exr: EXR alpha "
                                     "is premultiplied by definition");
    }
    if (o->slices && strcmp(argv[1], "render"))
        return usage_error("%s", "--slice and --slice-env are for render");
    /* --format: the diagnostics' form for every command but bake, whose
     * word names the cache format (read in cmd_bake). */
    if (o->format && strcmp(argv[1], "bake")) {
        bool validate = !strcmp(argv[1], "validate");
        o->sarif = validate && !strcmp(o->format, "sarif");
        if (strcmp(o->format, "text") && strcmp(o->format, "json") && !o->sarif)
            return usage_error(validate ? "--format takes 'text', 'json' or 'sarif', got '%s'"
                               : strcmp(argv[1], "render")
                                   ? "--format takes 'text' or 'json', got '%s'"
                                   : "--format takes 'text' or 'json' (diagnostics), or 'png' or "
                                     "'exr' (frames), got '%s'",
                               o->format);
        o->json = !strcmp(o->format, "json");
    }
    if (o->list_rules && strcmp(argv[1], "validate"))
        return usage_error("%s", "--list-rules is for validate");
    return -1;
}

/* --werror: true (with a line saying so) when l has warnings to fail on. */
static bool fails_on_warnings(const pfx_loaded *l, const char *path, const options *o) {
    if (!o->werror || l->diags.warnings == 0)
        return false;
    fprintf(stderr, "pfx: '%s': %d warning%s treated as error%s (--werror)\n", path,
            l->diags.warnings, l->diags.warnings == 1 ? "" : "s",
            l->diags.warnings == 1 ? "" : "s");
    return true;
}

/* Loads and compiles one file, printing its diagnostics. With --werror a
 * warning fails it: the effect stays in l (freed with it), unused. */
static pfx_effect *load(pfx_loaded *l, const char *path, const options *o) {
    pfx_effect *e = pfx_load(l, path, &o->compile);
    pfx_diags_print(&l->diags, stderr, o->json);
    return e && !fails_on_warnings(l, path, o) ? e : NULL;
}

static int cmd_validate(int argc, char **argv, const options *o) {
    if (o->list_rules) {
        pfx_rules_print(stdout);
        return 0;
    }
    if (optind >= argc)
        return usage_error("%s", "validate needs at least one FILE");
    int status = 0;
    /* --format sarif: every file's diagnostics gather into one log, written
     * to stdout at the end (stderr keeps the --werror lines and failures
     * to build or write the log). */
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    pfx_sarif *sarif = o->sarif ? pfx_sarif_create() : NULL;
    if (o->sarif && !sarif)
        pfx_diag_error(&run, PFX_RULE_OUT_OF_MEMORY, "out of memory for the SARIF log");
    for (int i = optind; i < argc && !run.errors; i++) {
        pfx_loaded l;
        pfx_effect *e = pfx_load(&l, argv[i], &o->compile);
        if (e) {
            /* The whole render, every frame: what it would cost. */
            pfx_estimate est;
            pfx_estimate_run(e, 0, pfx_effect_frame_count(e) - 1, true, &est);
            pfx_estimate_warn(&l, &est, o->max_memory);
        }
        if (sarif && !pfx_sarif_add(sarif, &l.diags))
            pfx_diag_error(&run, PFX_RULE_OUT_OF_MEMORY, "out of memory for the SARIF log");
        if (!sarif)
            pfx_diags_print(&l.diags, stderr, o->json);
        if (!e || fails_on_warnings(&l, argv[i], o))
            status = EXIT_INVALID;
        pfx_loaded_free(&l);
    }
    if (sarif && !run.errors && !pfx_sarif_write(sarif, stdout))
        pfx_diag_error(&run, PFX_RULE_WRITE_FAILED,
                       "cannot write the SARIF log to standard output");
    pfx_sarif_destroy(sarif);
    pfx_diags_print(&run, stderr, false);
    if (run.errors)
        status = EXIT_INVALID;
    pfx_diags_free(&run);
    return status;
}

/* mkdir -p */
static bool make_dirs(const char *path, pfx_diags *d) {
    char buf[4096];
    if (strlen(path) >= sizeof buf) {
        pfx_diag_error(d, PFX_RULE_TOO_LARGE, "output path is too long");
        return false;
    }
    strcpy(buf, path);
    for (char *p = buf + 1;; p++) {
        if (*p == '/' || *p == 0) {
            char saved = *p;
            *p = 0;
            struct stat st;
            if (mkdir(buf, 0777) != 0 && errno != EEXIST) {
                pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot create '%s': %s", buf,
                               strerror(errno));
                return false;
            }
            if (stat(buf, &st) != 0) { /* a symlink loop, a dangling link */
                pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot create '%s': %s", buf,
                               strerror(errno));
                return false;
            }
            if (!S_ISDIR(st.st_mode)) {
                pfx_diag_error(d, PFX_RULE_WRITE_FAILED, "cannot create '%s': %s", buf,
                               strerror(ENOTDIR));
                return false;
            }
            *p = saved;
            if (!saved)
                return true;
        }
    }
}

/* mkdir -p of the directory part of a file path. */
static bool make_parent_dirs(const char *path, pfx_diags *d) {
    const char *slash = strrchr(path, '/');
    if (!slash || slash == path)
        return true;
    char dir[4096];
    if ((size_t)(slash - path) >= sizeof dir) {
        pfx_diag_error(d, PFX_RULE_TOO_LARGE, "output path is too long");
        return false;
    }
    memcpy(dir, path, (size_t)(slash - path));
    dir[slash - path] = 0;
    return make_dirs(dir, d);
}

/* The file's name without directory and extension: out/fire_0000.png. */
static void file_stem(const char *path, char *out, size_t size) {
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    snprintf(out, size, "%s", base);
    char *dot = strrchr(out, '.');
    if (dot && dot != out)
        *dot = 0;
}

/* Resolves --frames against the effect's frame count; false if outside. */
static bool frame_range(const pfx_effect *e, const options *o, long *first, long *last) {
    long n = pfx_effect_frame_count(e);
    *first = o->has_frames ? o->first : 0;
    *last = o->has_frames && o->last >= 0 ? o->last : n - 1;
    /* A looping effect's frames go on for ever: frame f is frame f mod n. */
    if ((*last >= n && !(e->loop && *last < 1000000)) || *first > *last) {
        if (o->last < 0)
            fprintf(stderr, "pfx: --frames %ld: is outside the effect's frames 0:%ld\n", o->first,
                    n - 1);
        else
            fprintf(stderr, "pfx: --frames %ld:%ld is outside the effect's frames 0:%ld\n",
                    o->first, o->last, n - 1);
        return false;
    }
    return true;
}

/* Refuses, before anything is allocated, a run estimated to need more than
 * --max-memory (default half of physical memory), naming the biggest part. */
static bool memory_fits(const pfx_effect *e, long first, long last, bool render, const options *o,
                        pfx_diags *run) {
    pfx_estimate est;
    pfx_estimate_run(e, first, last, render | (o->motion_vectors ? PFX_ESTIMATE_MOTION_VECTORS : 0),
                     &est);
    if (!o->max_memory || est.total_bytes <= (double)o->max_memory)
        return true;
    char need[32], bound[32], part[32];
    pfx_diag_error(run, PFX_RULE_MEMORY_BOUND,
                   "this %s needs up to %s of memory, over the bound of %s (--max-memory, "
                   "default half of physical memory); the most goes to the %s: %s",
                   render ? "render" : "bake",
                   pfx_memory_format(est.total_bytes, need, sizeof need),
                   pfx_memory_format((double)o->max_memory, bound, sizeof bound),
                   pfx_memory_part_names[est.biggest],
                   pfx_memory_format(est.bytes[est.biggest], part, sizeof part));
    return false;
}

/* The manifest's settings common to render and bake (the effect's values
 * after --fps, --size, --seed and --max-particles), and its inputs. */
static bool describe_run(pfx_delivery *dl, const pfx_effect *e, long first, long last,
                         pfx_diags *d) {
    char seed[32];
    snprintf(seed, sizeof seed, "%llu", (unsigned long long)e->seed);
    pfx_manifest_set_range(dl->now, "frames", first, last);
    pfx_manifest_set_number(dl->now, "fps", e->fps);
    pfx_manifest_set_number(dl->now, "width", e->width);
    pfx_manifest_set_number(dl->now, "height", e->height);
    pfx_manifest_set_string(dl->now, "seed", seed);
    pfx_manifest_set_number(dl->now, "max_particles", (double)e->max_particles);
    pfx_manifest_set_number(dl->now, "loop", e->loop);
    return pfx_manifest_add_effect(dl->now, e, d);
}

/* Says that there was nothing to do, with the key that proved it. */
static void say_up_to_date(const options *o, const char *path, const char *where,
                           pfx_delivery *dl) {
    if (!o->quiet)
        fprintf(stderr,
                "pfx: '%s' is up to date in '%s' (bake key %.12s); nothing to do, --force "
                "redoes it\n",
                path, where, pfx_manifest_key(dl->now));
}

/* Renders one effect file into dir: the whole of `pfx render` for one FILE.
 * Returns the exit status. */
static int render_one(const char *path, const char *dir, pfx_renderer_kind kind, const options *o) {
    pfx_loaded l;
    pfx_effect *e = load(&l, path, o);
    int status = EXIT_INVALID;
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    char stem[256], manifest[4096 + 320];
    file_stem(path, stem, sizeof stem);
    snprintf(manifest, sizeof manifest, "%s/%s.manifest.json", dir, stem);
    pfx_render_job job = {.effect = e,
                          .dir = dir,
                          .stem = stem,
                          .format = o->frames_as,
                          .progress = !o->quiet && !o->progress_json && isatty(2)};
    pfx_progress progress;
    bool reporting = false;
    pfx_delivery dl = {.dir = dir,
                       .manifest_path = manifest,
                       .depfile = o->depfile,
                       .target = manifest,
                       .force = o->force};
    if (!e)
        goto done;
    if (!frame_range(e, o, &job.first, &job.last)) {
        status = EXIT_USAGE;
        goto done;
    }
    /* A slice: its part of the range, and a manifest of its own, so that
     * slices may share a directory. */
    long all_first = job.first, all_last = job.last;
    if (o->slices) {
        pfx_slice_range(all_first, all_last, o->slice, o->slices, &job.first, &job.last);
        snprintf(manifest, sizeof manifest, "%s/%s.slice-%04ld-of-%04ld.manifest.json", dir, stem,
                 o->slice, o->slices);
    }
    if (o->progress_json) {
        pfx_progress_init(&progress, stderr, path, job.last - job.first + 1);
        job.on_frame = pfx_progress_frame;
        job.on_frame_ctx = &progress;
        reporting = true;
    }
    if (!memory_fits(e, job.first, job.last, true, o, &run))
        goto done;
    /* The renderer before the directory: one that cannot start writes
     * nothing. */
    job.renderer = pfx_renderer_create(kind, e->width, e->height, &run);
    if (!job.renderer || !make_dirs(dir, &run))
        goto done;
    if (!pfx_delivery_begin(&dl, "render", &run) ||
        !describe_run(&dl, e, job.first, job.last, &run))
        goto done;
    pfx_manifest_set_string(dl.now, "renderer", pfx_renderer_name(job.renderer));
    if (o->frames_as != PFX_FRAME_PNG) /* PNG, the default, keeps the keys it had */
        pfx_manifest_set_string(dl.now, "format", pfx_frame_format_name(o->frames_as));
    if (o->slices)
        pfx_manifest_set_slice(dl.now, o->slice, o->slices, all_first, all_last);
    pfx_atlas_layout atlas = o->atlas_layout;
    if (o->atlas) {
        /* The sheet's size is known now but for --crop, which only makes
         * it smaller: one that cannot be made fails before any frame. */
        pfx_atlas_layout check = atlas;
        check.frame_w = e->width;
        check.frame_h = e->height;
        check.frames = (int)(job.last - job.first + 1);
        if (!pfx_atlas_layout_resolve(&check, &run))
            goto done;
        pfx_atlas_job_describe(&atlas, dl.now);
    }
    if (o->preview)
        pfx_manifest_set_string(dl.now, "preview", o->preview);
    pfx_mv_meta mv = {
        .max_px = o->mv_max, .max_given = o->mv_max > 0, .flip_y = o->mv_flip_y, .fps = e->fps};
    if (o->motion_vectors)
        pfx_mv_describe(&mv, dl.now);
    if (pfx_delivery_up_to_date(&dl) && (!o->preview || access(o->preview, F_OK) == 0)) {
        if (pfx_delivery_skip(&dl, &run)) {
            say_up_to_date(o, path, dir, &dl);
            status = 0;
        }
        goto done;
    }
    /* --motion-vectors: one scale for the whole sequence, whatever the
     * range, unless --mv-max gives it. */
    if (o->motion_vectors) {
        if (!mv.max_given && !pfx_mv_sequence_max(e, &mv.max_px, &run))
            goto done;
        job.motion = &mv;
        atlas.motion = &mv;
    }
    if (!(o->jobs > 1 ? pfx_render_job_run_parallel(&job, kind, o->jobs, &run)
                      : pfx_render_job_run(&job, &run)))
        goto done;
    for (long f = job.first; f <= job.last; f++) {
        char name[300];
        snprintf(name, sizeof name, "%s_%04ld.%s", stem, f, pfx_frame_format_name(o->frames_as));
        if (!pfx_manifest_add_output(dl.now, dir, name, &run))
            goto done;
    }
    if (o->motion_vectors &&
        (!pfx_mv_add_outputs(dl.now, dir, stem, job.first, job.last, &run) ||
         (!o->atlas && !pfx_mv_sidecar_run(dir, stem, job.first, job.last, &mv, dl.now, &run))))
        goto done;
    if (o->atlas &&
        !pfx_atlas_job_run(dir, stem, job.first, job.last, e->fps, e->loop, &atlas, dl.now, &run))
        goto done;
    if (o->preview && !pfx_preview_run(dir, stem, job.first, job.last, e->fps, o->preview, &run))
        goto done;
    if (!pfx_delivery_finish(&dl, &run))
        goto done;
    if (!o->quiet) {
        pfx_sim_note_dropped(job.sim, &run);
        if (job.first > job.last)
            fprintf(stderr, "pfx: slice %ld of %ld of '%s' has no frames (%ld frames in all)",
                    o->slice, o->slices, path, all_last - all_first + 1);
        else
            fprintf(stderr, "pfx: rendered '%s': %ld frames (%ld to %ld) in '%s'", path,
                    job.frames_done, job.first, job.last, dir);
        if (o->slices && job.first <= job.last)
            fprintf(stderr, ", slice %ld of %ld", o->slice, o->slices);
        if (o->atlas)
            fprintf(stderr, ", atlas %dx%d of %dx%d", atlas.columns, atlas.rows, atlas.width,
                    atlas.height);
        if (o->preview)
            fprintf(stderr, ", preview '%s'", o->preview);
        if (o->motion_vectors)
            fprintf(stderr, ", motion vectors up to %g px", mv.max_px);
        if (dl.stale_removed)
            fprintf(stderr, ", %zu stale removed", dl.stale_removed);
        fputc('\n', stderr);
    }
    status = 0;
done:
    pfx_diags_print(&run, stderr, false);
    if (reporting)
        pfx_progress_finish(&progress, status);
    pfx_diags_free(&run);
    pfx_delivery_free(&dl);
    pfx_renderer_destroy(job.renderer);
    pfx_render_job_free(&job);
    pfx_loaded_free(&l);
    return status;
}

/* pfx render FILE... -o DIR: one file into DIR, several each into
 * DIR/<name>/, one after another (-j works inside each); the exit status is
 * the worst, and the first failure stops the rest unless --keep-going. */
static int cmd_render(int argc, char **argv, const options *o) {
    if (optind >= argc)
        return usage_error("%s", "render needs a FILE and -o DIR");
    if (!o->output)
        return usage_error("%s", "render needs -o DIR");
    int files = argc - optind;
    if (files > 1 && o->depfile)
        return usage_error("%s", "--depfile names one target: give one FILE");
    for (int i = optind; i < argc; i++)
        for (int k = optind; k < i; k++) {
            char a[256], b[256];
            file_stem(argv[i], a, sizeof a);
            file_stem(argv[k], b, sizeof b);
            if (!strcmp(a, b))
                return usage_error("two effects would render into '%s': rename one", a);
        }
    pfx_renderer_kind kind;
    if (!renderer_kind(o, &kind))
        return EXIT_USAGE;
    int worst = 0;
    for (int i = optind; i < argc; i++) {
        char dir[4096], stem[256];
        file_stem(argv[i], stem, sizeof stem);
        snprintf(dir, sizeof dir, "%s/%s", o->output, stem);
        int status = render_one(argv[i], files > 1 ? dir : o->output, kind, o);
        if (status > worst)
            worst = status;
        if (status && !o->keep_going) {
            if (i + 1 < argc)
                fprintf(stderr,
                        "pfx: stopped after '%s' failed; %d file%s not rendered "
                        "(--keep-going renders them)\n",
                        argv[i], argc - i - 1, argc - i - 1 == 1 ? "" : "s");
            break;
        }
    }
    return worst;
}

/* The bake's format: --format, else the output's extension (.ply, .pcache),
 * else CSV. False (after the usage error) on a word that names none. */
static bool bake_format(const options *o, pfx_bake_format *f) {
    *f = PFX_BAKE_CSV;
    if (o->format) {
        if (pfx_bake_format_parse(o->format, f))
            return true;
        usage_error("bake --format takes 'csv', 'ply' or 'pcache', got '%s'", o->format);
        return false;
    }
    const char *dot = strrchr(o->output, '.');
    if (dot && !strchr(dot, '/'))
        pfx_bake_format_parse(dot + 1, f);
    return true;
}

static int cmd_bake(int argc, char **argv, const options *o) {
    if (optind != argc - 1)
        return usage_error("%s", "bake takes one FILE and -o OUT");
    if (!o->output)
        return usage_error("%s", "bake needs -o OUT (a .csv, .ply or .pcache file, or - for "
                                 "standard output)");
    pfx_bake_format format;
    if (!bake_format(o, &format))
        return EXIT_USAGE;
    bool to_stdout = !strcmp(o->output, "-");
    if (to_stdout && o->depfile)
        return usage_error("%s", "--depfile needs a file to name as its target, not -o -");
    pfx_loaded l;
    pfx_effect *e = load(&l, argv[optind], o);
    int status = EXIT_INVALID;
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    long first, last;
    pfx_sim *sim = NULL, *view = NULL;
    pfx_bake *b = NULL;
    /* The manifest: OUT.manifest.json beside OUT (none for standard
     * output), listing OUT by its name. */
    char dir[4096] = ".", manifest[4200];
    const char *name = o->output, *slash = strrchr(o->output, '/');
    if (slash) {
        snprintf(dir, sizeof dir, "%.*s", slash == o->output ? 1 : (int)(slash - o->output),
                 o->output);
        name = slash + 1;
    }
    snprintf(manifest, sizeof manifest, "%s.manifest.json", o->output);
    pfx_delivery dl = {.dir = dir,
                       .manifest_path = to_stdout ? NULL : manifest,
                       .depfile = o->depfile,
                       .target = o->output,
                       .force = o->force};
    if (!e)
        goto done;
    if (!frame_range(e, o, &first, &last)) {
        status = EXIT_USAGE;
        goto done;
    }
    if (!memory_fits(e, first, last, false, o, &run))
        goto done;
    if (!pfx_delivery_begin(&dl, "bake", &run) || !describe_run(&dl, e, first, last, &run))
        goto done;
    pfx_manifest_set_string(dl.now, "format", pfx_bake_format_name(format));
    pfx_manifest_set_number(dl.now, "every", (double)o->every);
    if (!to_stdout && pfx_delivery_up_to_date(&dl)) {
        if (pfx_delivery_skip(&dl, &run)) {
            say_up_to_date(o, argv[optind], o->output, &dl);
            status = 0;
        }
        goto done;
    }
    sim = pfx_sim_create(e, &run);
    view = pfx_sim_create(e, &run);
    if (!sim || !view) {
        pfx_diag_error(&run, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    if (!to_stdout && !make_parent_dirs(o->output, &run))
        goto done;
    b = pfx_bake_open(o->output, format, e, &run);
    if (!b)
        goto done;
    bool ok = true;
    for (long f = first; f <= last && ok; f++) {
        const pfx_sim *state = pfx_sim_frame(sim, view, f);
        if (sim->failed || view->failed) {
            ok = false;
            break;
        }
        if ((f - first) % o->every == 0)
            ok = pfx_bake_frame(b, state, f, pfx_sim_frame_time(e, f));
    }
    if (!pfx_bake_close(b, ok, &run) || !ok) {
        if (!run.errors)
            pfx_diag_error(&run, PFX_RULE_WRITE_FAILED, "cannot write the bake");
        goto done;
    }
    if (!to_stdout &&
        (!pfx_manifest_add_output(dl.now, dir, name, &run) || !pfx_delivery_finish(&dl, &run)))
        goto done;
    if (!o->quiet) {
        pfx_sim_note_dropped(sim, &run);
        fprintf(stderr, "pfx: baked '%s': frames %ld to %ld as %s to '%s'\n", argv[optind], first,
                last, pfx_bake_format_name(format), to_stdout ? "standard output" : o->output);
    }
    status = 0;
done:
    pfx_diags_print(&run, stderr, false);
    pfx_diags_free(&run);
    pfx_delivery_free(&dl);
    pfx_sim_destroy(view);
    pfx_sim_destroy(sim);
    pfx_loaded_free(&l);
    return status;
}

/* The estimate of a whole render, every frame, before anything is allocated:
 * work as particle-steps and memory by part (jobs/estimate.c). */
static void print_estimate(const pfx_effect *e) {
    pfx_estimate est;
    char b[32];
    pfx_estimate_run(e, 0, pfx_effect_frame_count(e) - 1, true, &est);
    printf("  work to the last frame, at most: %.4g steps, %.4g particle-steps, %.4g sprites "
           "covering %.4g pixels\n",
           est.steps, est.particle_steps, est.sprites, est.sprite_pixels);
    printf("  memory of a render, at most %s:\n", pfx_memory_format(est.total_bytes, b, sizeof b));
    for (int p = 0; p < PFX_MEMORY_PART_COUNT; p++)
        if (est.bytes[p] > 0)
            printf("    %s: %s%s\n", pfx_memory_part_names[p],
                   pfx_memory_format(est.bytes[p], b, sizeof b),
                   p == (int)est.biggest ? " (the most)" : "");
    char c[32];
    printf("  2 x pools + %d threads x %s = %s: %s\n", est.threads,
           pfx_memory_format(est.per_thread_bytes, b, sizeof b),
           pfx_memory_format(est.bound_bytes, c, sizeof c),
           est.total_bytes <= est.bound_bytes
               ? "the estimate is within it"
               : "the estimate is over it (parts that grow with the sprites or the image)");
}

/* pfx info --format json: the figures of the text form that scripts use
 * (sizes, pools, the estimate) as one JSON object on standard output. */
static int print_info_json(const pfx_effect *e, const options *o) {
    json_t *emitters = json_array();
    double bytes = 0;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        const size_t bpp = pfx_sim_bytes_per_particle(e, i);
        bytes += (double)em->capacity * (double)bpp;
        json_array_append_new(emitters, json_pack("{s:s, s:I, s:I}", "name", em->name, "capacity",
                                                  (json_int_t)em->capacity, "bytes_per_particle",
                                                  (json_int_t)bpp));
    }
    pfx_estimate est;
    pfx_estimate_run(e, 0, pfx_effect_frame_count(e) - 1, true, &est);
    json_t *root = json_pack("{s:s, s:I, s:i, s:i, s:o, s:f, s:b}", "effect", e->path, "frames",
                             (json_int_t)pfx_effect_frame_count(e), "width", e->width, "height",
                             e->height, "emitters", emitters, "pool_bytes", bytes, "depth_sort",
                             pfx_sprites_need_sort(e));
    json_t *estimate = pfx_estimate_json(&est);
    if (root && estimate) {
        json_object_update(root, estimate);
        if (o->max_memory)
            json_object_set_new(root, "max_memory_bytes", json_real((double)o->max_memory));
    }
    json_decref(estimate);
    char *text = root ? json_dumps(root, JSON_INDENT(2) | JSON_PRESERVE_ORDER) : NULL;
    json_decref(root);
    if (!text) {
        fprintf(stderr, "pfx: out of memory\n");
        return EXIT_INVALID;
    }
    printf("%s\n", text);
    free(text);
    return 0;
}

static int cmd_info(int argc, char **argv, const options *o) {
    if (optind != argc - 1)
        return usage_error("%s", "info takes one FILE");
    pfx_loaded l;
    pfx_effect *e = load(&l, argv[optind], o);
    if (!e) {
        pfx_loaded_free(&l);
        return EXIT_INVALID;
    }
    if (o->json) {
        int status = print_info_json(e, o);
        pfx_loaded_free(&l);
        return status;
    }
    double steps_per_frame = e->sim_rate / e->fps;
    printf("effect %s\n", e->path);
    printf("  frames %ld (%g s at %g fps), image %dx%d\n", pfx_effect_frame_count(e), e->duration,
           e->fps, e->width, e->height);
    printf("  simulation %g steps/s (dt %.6g s), %.4g steps per frame, prewarm %g s, seed %llu\n",
           e->sim_rate, 1.0 / e->sim_rate, steps_per_frame, e->prewarm,
           (unsigned long long)e->seed);
    if (e->loop)
        printf("  loops every %g s (%ld frames), shown from t = %g s when every particle alive "
               "is periodic\n",
               e->duration, e->loop_frames, e->loop_start);
    printf("  forces %zu\n", e->force_count);
    for (size_t i = 0; i < e->force_count; i++)
        printf("    %s: %s%s\n", e->forces[i].name,
               pfx_kind_name(pfx_force_names, (int)e->forces[i].spec.kind),
               e->forces[i].spec.region.kind ? " (in a region)" : "");
    size_t total = 0, bytes = 0;
    printf("  emitters %zu\n", e->emitter_count);
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        size_t bpp = pfx_sim_bytes_per_particle(e, i);
        printf("    %s: %s shape, %s rate up to %g particles/s%s%s, lifetime up to %g s, %s "
               "blend\n",
               em->name, pfx_kind_name(pfx_shape_names, (int)em->shape.type),
               pfx_kind_name(pfx_rate_kind_names, (int)em->rate_kind), pfx_emitter_max_rate(em),
               em->burst_count ? " plus bursts" : "",
               em->spawned_peak > 0 ? " plus sub-emitters" : "", em->max_lifetime,
               em->blend == PFX_BLEND_ADD ? "additive" : "alpha");
        printf("      pool %u particles x %zu bytes = %zu bytes%s\n", em->capacity, bpp,
               em->capacity * bpp, em->saturates ? " (saturates: cut by the budget)" : "");
        if (em->motion)
            printf("      integrator: %s\n", em->motion->choice.why);
        else if (em->accel[0] == 0 && em->accel[1] == 0 && em->accel[2] == 0)
            printf("      integrator: exact (no force: straight lines)\n");
        else
            printf("      integrator: exact (only gravity, [%g, %g, %g] m/s^2%s: the "
                   "constant-acceleration closed form, exact at any step)\n",
                   em->accel[0], em->accel[1], em->accel[2],
                   em->gravity_scale.dist == PFX_DIST_CONST ? "" : " x gravity_scale");
        if (em->deflector_count) {
            printf("      deflectors:");
            for (size_t d = 0; d < em->deflector_count; d++)
                printf(" %s", em->deflectors[d].name);
            printf(" (swept exact hits; 24 scratch bytes per particle)\n");
        }
        for (size_t k = 0; k < em->spawn_count; k++)
            printf("      %s -> %s\n",
                   pfx_kind_name(pfx_spawn_event_names, (int)em->spawns[k].event),
                   e->emitters[em->spawns[k].target].name);
        if (em->kill)
            printf("      kill rules: %zu%s\n", em->kill->count,
                   em->kill->bounds == PFX_BOUNDS_WRAP   ? ", wrapping bounds"
                   : em->kill->bounds == PFX_BOUNDS_KILL ? ", killing bounds"
                                                         : "");
        total += em->capacity;
        bytes += em->capacity * bpp;
    }
    printf("  particles at most %zu of the %llu budget, %zu bytes\n", total,
           (unsigned long long)e->max_particles, bytes);
    printf("  depth sort: %s\n", pfx_sprites_need_sort(e)
                                     ? "yes (a sprite emitter blends by alpha)"
                                     : "no (no sprite emitter blends by alpha)");
    print_estimate(e);
    if (o->max_memory) {
        char b[32];
        printf("  memory bound %s (--max-memory)\n",
               pfx_memory_format((double)o->max_memory, b, sizeof b));
    }
    pfx_loaded_free(&l);
    return 0;
}

/* pfx assemble DIR... -o OUT: the slices of renders into one directory. */
static int cmd_assemble(int argc, char **argv, const options *o) {
    if (optind >= argc)
        return usage_error("%s", "assemble needs at least one DIR (with the slices' frames)");
    if (!o->output)
        return usage_error("%s", "assemble needs -o OUT");
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    pfx_assemble_report r;
    pfx_assemble_options opt = {.atlas = o->atlas ? &o->atlas_layout : NULL, .preview = o->preview};
    bool ok = make_dirs(o->output, &run) &&
              pfx_assemble((const char *const *)argv + optind, (size_t)(argc - optind), o->output,
                           &opt, &r, &run);
    if (ok && !o->quiet)
        fprintf(stderr,
                "pfx: assembled %zu frames of %zu render%s in '%s' (%zu linked, %zu copied, %zu "
                "already there)\n",
                r.frames, r.effects, r.effects == 1 ? "" : "s", o->output, r.linked, r.copied,
                r.kept);
    pfx_diags_print(&run, stderr, false);
    pfx_diags_free(&run);
    return ok ? 0 : EXIT_INVALID;
}

/* The JSON Schema of the effect format, from the key tables. */
static int cmd_schema(int argc, char **argv) {
    if (optind != argc)
        return usage_error("%s", "schema takes no FILE");
    (void)argv;
    char *text = pfx_schema_text();
    if (!text) {
        fputs("pfx: out of memory\n", stderr);
        return EXIT_INVALID;
    }
    puts(text);
    free(text);
    return ferror(stdout) ? EXIT_INVALID : 0;
}

static int cmd_bench(int argc, char **argv, const options *o) {
    if (optind < argc && !strcmp(argv[optind], "accuracy")) {
        if (!o->output)
            return usage_error("%s", "bench accuracy needs -o DIR");
        return pfx_bench_accuracy(o->output, stdout) == 0 ? 0 : EXIT_INVALID;
    }
    if (optind < argc)
        return usage_error("unknown benchmark '%s'; try 'accuracy'", argv[optind]);
    pfx_renderer_kind kind;
    if (!renderer_kind(o, &kind))
        return EXIT_USAGE;
    /* The rendering half draws the fire example: from the source tree, or
     * PFX_FIRE_EFFECT. */
    const char *fire = getenv("PFX_FIRE_EFFECT");
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    bool ok = pfx_bench_speed(stdout, fire ? fire : "effects/fire.yaml", kind, o->bench_json, &run);
    pfx_diags_print(&run, stderr, false);
    pfx_diags_free(&run);
    return ok ? 0 : EXIT_INVALID;
}

static const char *const commands[] = {"validate", "render", "bake",     "info",
                                       "bench",    "schema", "assemble", NULL};

int main(int argc, char **argv) {
    /* Before any thread starts: a signal removes the temporary files. */
    pfx_atomic_guard_signals();
    if (argc < 2)
        return usage_error("%s", "no command given");
    const char *cmd = argv[1];
    if (!strcmp(cmd, "-h") || !strcmp(cmd, "--help") || !strcmp(cmd, "help")) {
        fputs(usage_text, stdout);
        return 0;
    }
    if (!strcmp(cmd, "--version")) {
        puts("pfx 0.1.0");
        return 0;
    }
    options o;
    int stop = parse_options(argc, argv, &o);
    if (stop >= 0)
        return stop;
    if (!strcmp(cmd, "validate"))
        return cmd_validate(argc, argv, &o);
    if (!strcmp(cmd, "render"))
        return cmd_render(argc, argv, &o);
    if (!strcmp(cmd, "bake"))
        return cmd_bake(argc, argv, &o);
    if (!strcmp(cmd, "info"))
        return cmd_info(argc, argv, &o);
    if (!strcmp(cmd, "bench"))
        return cmd_bench(argc, argv, &o);
    if (!strcmp(cmd, "schema"))
        return cmd_schema(argc, argv);
    if (!strcmp(cmd, "assemble"))
        return cmd_assemble(argc, argv, &o);
    const char *sug = pfx_suggest(cmd, commands);
    if (sug) {
        fprintf(stderr, "pfx: unknown command '%s'; did you mean '%s'?\n", cmd, sug);
        fputs("Try 'pfx --help' for more information.\n", stderr);
        return EXIT_USAGE;
    }
    return usage_error("unknown command '%s'", cmd);
}
