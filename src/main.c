/* The pfx command: argv -> options, checked, then the command the first
 * word names (src/commands/: one file a command, each running the stages in
 * order: load, compile, simulate, render or bake, write), whose result is
 * the exit status: 0 success, 1 invalid input or I/O failure, 2 usage
 * error. It is the only file that reads argv or the usage text. */
#include <errno.h>
#include <getopt.h>
#include <string.h>

#include "commands/commands.h"
#include "compile/read.h"
#include "jobs/estimate.h"
#include "jobs/slice.h"
#include "output/atomic_file.h"
#include "output/mp4.h"

static bool parse_ulong(const char *s, unsigned long long *out) {
    if (!s || !*s || *s == '-')
        return false;
    char *end;
    errno = 0;
    *out = strtoull(s, &end, 10);
    return errno == 0 && *end == 0;
}

/* --frames: N (one frame), A:B, or A: (from A to the end, last = -1), each
 * with an optional :S after it (A:B:S, A::S): every S-th frame from A. */
static bool parse_frames(const char *arg, pfx_cli *o) {
    char buf[64];
    unsigned long long a, b = 0, step = 0;
    if (strlen(arg) >= sizeof buf)
        return false;
    strcpy(buf, arg);
    char *colon = strchr(buf, ':');
    if (colon)
        *colon = 0;
    char *colon2 = colon ? strchr(colon + 1, ':') : NULL;
    if (colon2) {
        *colon2 = 0;
        if (!parse_ulong(colon2 + 1, &step) || step < 1 || step > 100000000)
            return false;
    }
    if (!parse_ulong(buf, &a) || a > 100000000)
        return false;
    bool to_end = colon && colon[1] == 0;
    if (!colon)
        b = a;
    else if (!to_end && (!parse_ulong(colon + 1, &b) || b < a || b > 100000000))
        return false;
    o->first = (long)a;
    o->last = to_end ? -1 : (long)b;
    o->frames_step = (long)step;
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

/* The values past 255 name the long options without a short form. */
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
    OPT_PREVIEW_Q,
    OPT_ATLAS_POT,
    OPT_ATLAS_JSON,
    OPT_SET,
    OPT_MOTION_VECTORS,
    OPT_MV_MAX,
    OPT_MV_FLIP_Y,
    OPT_PORT,
    OPT_HOST,
    OPT_NO_OPEN,
    OPT_TOLERANCE,
    OPT_COMPARE
};

/* The commands, as bits: which take an option (and list it in their help). */
enum {
    CMD_VALIDATE = 1 << 0,
    CMD_RENDER = 1 << 1,
    CMD_BAKE = 1 << 2,
    CMD_INFO = 1 << 3,
    CMD_BENCH = 1 << 4,
    CMD_ASSEMBLE = 1 << 5,
    CMD_SCHEMA = 1 << 6,
    CMD_PREVIEW = 1 << 7,
    CMD_WATCH = 1 << 8, /* takes render's options as well */
    CMD_LSP = 1 << 9,
    CMD_TUNE = 1 << 10,
    CMD_ALL = (1 << 11) - 1,
    CMD_NONE = 0 /* pfx alone: --version */
};

/* The options, one row each, in the order `pfx --help` lists them: getopt's
 * table and every help text come from these rows. `shown` is the option as
 * the help spells it; `help` its lines (joined by \n, each set in the
 * column); `commands` the commands whose help lists it. */
typedef struct option_row {
    const char *name;
    int has_arg, val; /* as in struct option; val 0: not one of getopt's */
    const char *shown;
    unsigned commands;
    const char *help;
} option_row;

static const option_row option_rows[] = {
    {"output", required_argument, 'o', "-o, --output PATH",
     CMD_RENDER | CMD_BAKE | CMD_BENCH | CMD_ASSEMBLE | CMD_TUNE,
     "output directory (render, tune, bench accuracy) or\n"
     "file (bake; - is standard output; a run of # in its\n"
     "name, as in cache_####.ply: one file a frame, # the\n"
     "frame number)"},
    {"frames", required_argument, OPT_FRAMES, "    --frames A:B[:S]",
     CMD_RENDER | CMD_BAKE | CMD_TUNE,
     "only frames A to B inclusive (with S: every S-th from A),\n"
     "numbered as in a full render"},
    {"size", required_argument, OPT_SIZE, "    --size WxH", CMD_RENDER | CMD_PREVIEW,
     "image size in pixels, overriding image.size"},
    {"fps", required_argument, OPT_FPS, "    --fps N", CMD_RENDER | CMD_BAKE,
     "output frames per second, overriding fps"},
    {"seed", required_argument, OPT_SEED, "    --seed N",
     CMD_RENDER | CMD_BAKE | CMD_INFO | CMD_PREVIEW, "random seed, overriding seed"},
    {"set", required_argument, OPT_SET, "    --set PATH=VALUE",
     CMD_VALIDATE | CMD_RENDER | CMD_BAKE | CMD_INFO | CMD_PREVIEW | CMD_TUNE,
     "override a value of the file, such as\n"
     "emitters.flame.rate=300 or 'emitters.flame.color=[1,0,0]'\n"
     "(VALUE is YAML; repeatable, applied in order)"},
    {"max-particles", required_argument, OPT_MAX, "    --max-particles N",
     CMD_VALIDATE | CMD_RENDER | CMD_BAKE | CMD_INFO,
     "particle budget over all emitters (default 1000000)"},
    {"max-memory", required_argument, OPT_MAX_MEMORY, "    --max-memory SIZE",
     CMD_VALIDATE | CMD_RENDER | CMD_BAKE | CMD_INFO | CMD_PREVIEW,
     "refuse a run estimated to need more (K, M, G, T;\ndefault half of physical memory)"},
    {"every", required_argument, OPT_EVERY, "    --every N", CMD_BAKE,
     "bake every Nth frame (default 1)"},
    {"format", required_argument, OPT_FORMAT, "    --format FMT",
     CMD_VALIDATE | CMD_RENDER | CMD_BAKE | CMD_INFO,
     "diagnostics as 'text' (default) or 'json' lines, or for\n"
     "validate one SARIF 2.1.0 log on stdout ('sarif'); for bake,\n"
     "the cache: csv, ply or pcache (default: from the extension);\n"
     "for render also the frames: png (default) or exr (linear\n"
     "half-float RGBA, premultiplied, exposure but no tone curve)"},
    {"list-rules", no_argument, OPT_LIST_RULES, "    --list-rules", CMD_VALIDATE,
     "validate: print every diagnostic's rule id, severity, name\nand meaning"},
    {"jobs", required_argument, 'j', "-j, --jobs N", CMD_RENDER,
     "render with N threads, each a contiguous part of the frames"},
    {"keep-going", no_argument, OPT_KEEP_GOING, "    --keep-going", CMD_RENDER,
     "render the other FILEs after one fails"},
    {"atlas", optional_argument, OPT_ATLAS, "    --atlas[=CxR]", CMD_RENDER | CMD_ASSEMBLE,
     "also pack the frames into <name>_atlas.png, a grid of C x R\n"
     "(default: from the frame count), and <name>_atlas.json"},
    {"padding", required_argument, OPT_PADDING, "    --padding N", CMD_RENDER | CMD_ASSEMBLE,
     "atlas: pixels around each frame in its cell (default 2)"},
    {"extrude", required_argument, OPT_EXTRUDE, "    --extrude N", CMD_RENDER | CMD_ASSEMBLE,
     "atlas: of those, how many repeat the frame's edge (default 1)"},
    {"crop", no_argument, OPT_CROP, "    --crop", CMD_RENDER | CMD_ASSEMBLE,
     "atlas: cut every frame to one box around all visible pixels"},
    {"atlas-pot", no_argument, OPT_ATLAS_POT, "    --atlas-pot", CMD_RENDER | CMD_ASSEMBLE,
     "atlas: pad the sheet to power-of-two sides"},
    {"atlas-json", required_argument, OPT_ATLAS_JSON, "    --atlas-json FORM",
     CMD_RENDER | CMD_ASSEMBLE, "atlas: TexturePacker's 'hash' (default) or 'array' JSON"},
    {"preview", required_argument, OPT_PREVIEW, "    --preview OUT", CMD_RENDER | CMD_ASSEMBLE,
     "also write the frames as a looping animated WebP (lossless;\n"
     "OUT.webp) or an H.264 MP4 (OUT.mp4, through the ffmpeg on\n"
     "the PATH)"},
    {"preview-quality", required_argument, OPT_PREVIEW_Q, "    --preview-quality Q",
     CMD_RENDER | CMD_ASSEMBLE,
     "a lossy WebP of quality Q (0..100), or the MP4 at\n"
     "x264 CRF (100-Q)*0.51 (default: lossless WebP, CRF 18)"},
    {"motion-vectors", no_argument, OPT_MOTION_VECTORS, "    --motion-vectors",
     CMD_RENDER | CMD_INFO,
     "also write <name>_mv_NNNN.png: 16-bit motion to the next\n"
     "frame, R right, G up, 0.5 none (with --atlas: a sheet)"},
    {"mv-max", required_argument, OPT_MV_MAX, "    --mv-max PIXELS", CMD_RENDER,
     "the displacement that encodes as 0 or 1 (default: the\nlargest in the sequence)"},
    {"mv-flip-y", no_argument, OPT_MV_FLIP_Y, "    --mv-flip-y", CMD_RENDER,
     "motion vectors with G = down (V down, as in Unreal)"},
    {"werror", no_argument, OPT_WERROR, "    --werror", CMD_VALIDATE,
     "treat warnings in an effect as errors (exit status 1),\n"
     "except those its 'allow:' acknowledges"},
    {"progress", required_argument, OPT_PROGRESS, "    --progress json", CMD_RENDER,
     "a JSON line on stderr per frame drawn, and one at the end"},
    {"tolerance", required_argument, OPT_TOLERANCE, "    --tolerance TOL", CMD_TUNE,
     "tune: the error allowed, on screen (0.5px, the default)\n"
     "or in space (1mm, 2cm, 0.01m)"},
    {"json", no_argument, OPT_JSON, "    --json", CMD_BENCH,
     "bench: the figures as one JSON object"},
    {"threads", required_argument, OPT_THREADS, "    --threads N", CMD_RENDER | CMD_BAKE | CMD_INFO,
     "simulation threads (default: PFX_THREADS, else the\n"
     "machine's cores); the output is the same for any N"},
    {"renderer", required_argument, OPT_RENDERER, "    --renderer R",
     CMD_RENDER | CMD_BENCH | CMD_PREVIEW,
     "how to get OpenGL (render, bench): auto (default: osmesa\n"
     "where built, else egl-cpu), osmesa, egl-cpu, egl-gpu"},
    {"force", no_argument, OPT_FORCE, "    --force", CMD_RENDER | CMD_BAKE,
     "render or bake even when DIR/<name>.manifest.json (or\n"
     "OUT.manifest.json) says the outputs are up to date"},
    {"depfile", required_argument, OPT_DEPFILE, "    --depfile FILE", CMD_RENDER | CMD_BAKE,
     "also write FILE: a Make rule naming every input read\n"
     "(a path make or ninja would misread is refused)"},
    {"slice", required_argument, OPT_SLICE, "    --slice I/N", CMD_RENDER,
     "render only slice I (from 0) of N contiguous frame ranges"},
    {"slice-env", required_argument, OPT_SLICE_ENV, "    --slice-env VAR", CMD_RENDER,
     "the slice index from $VAR (SLURM_ARRAY_TASK_ID,\n"
     "JOB_COMPLETION_INDEX, ...), with --slice-count N"},
    {"slice-count", required_argument, OPT_SLICE_COUNT, "    --slice-count N", CMD_RENDER,
     "the number of slices for --slice-env"},
    {"alpha", required_argument, OPT_ALPHA, "    --alpha MODE", CMD_RENDER | CMD_PREVIEW,
     "PNG alpha: straight or premultiplied, overriding\nimage.alpha"},
    {"port", required_argument, OPT_PORT, "    --port N", CMD_PREVIEW,
     "preview: the port (default 0: a free one)"},
    {"host", required_argument, OPT_HOST, "    --host ADDR", CMD_PREVIEW,
     "preview: listen on ADDR instead of 127.0.0.1 (a warning)"},
    {"no-open", no_argument, OPT_NO_OPEN, "    --no-open", CMD_PREVIEW,
     "preview: do not open the page in a browser"},
    {"compare", required_argument, OPT_COMPARE, "    --compare FILE", CMD_PREVIEW,
     "preview: A/B against FILE (the page can also pick\na file or a seed)"},
    {"quiet", no_argument, 'q', "-q, --quiet", CMD_ALL & ~(CMD_SCHEMA | CMD_LSP),
     "no progress line, summary line or notes"},
    {"help", no_argument, 'h', "-h, --help", CMD_ALL, "show this help"},
    {"version", no_argument, 0, "    --version", CMD_NONE, "show the version"},
};
enum { OPTION_ROW_COUNT = sizeof option_rows / sizeof option_rows[0] };

/* getopt's tables, made from the rows once (main): the long options, and
 * the short ones as ":o:j:qh" (the leading colon: a missing value is ':'). */
static struct option longopts[OPTION_ROW_COUNT + 1];
static char shortopts[2 + 2 * OPTION_ROW_COUNT];

static void make_getopt_tables(void) {
    int n = 0, k = 0;
    shortopts[k++] = ':';
    for (int i = 0; i < OPTION_ROW_COUNT; i++) {
        const option_row *r = &option_rows[i];
        if (!r->val)
            continue;
        longopts[n++] = (struct option){r->name, r->has_arg, 0, r->val};
        if (r->val < 256) {
            shortopts[k++] = (char)r->val;
            if (r->has_arg == required_argument)
                shortopts[k++] = ':';
        }
    }
}

/* The commands, one row each: the name argv[1] gives, its bit in the
 * option rows, its usage lines (after "usage: " or its indent), its line in
 * `pfx --help`, and what runs it. The names also feed the suggestion for a
 * mistyped command. */
typedef int (*command_fn)(const char *const *operands, int count, const pfx_cli *o);
typedef struct command_row {
    const char *name;
    unsigned bit;
    const char *usage, *summary;
    command_fn run;
} command_row;

static const command_row commands[] = {
    {"validate", CMD_VALIDATE,
     "pfx validate [--format text|json|sarif] [--werror] [--max-particles N]\n"
     "           [--max-memory SIZE] [--set PATH=VALUE] [-q] FILE...\n"
     "pfx validate --list-rules",
     "check effect files like a compiler; exit 1 if any has an error", pfx_cmd_validate},
    {"render", CMD_RENDER,
     "pfx render FILE... -o DIR [-j N] [--keep-going] [--frames A:B[:S]]\n"
     "           [--size WxH] [--fps N] [--seed N] [--max-particles N]\n"
     "           [--max-memory SIZE] [--renderer R] [--alpha MODE] [--threads N]\n"
     "           [--force] [--depfile FILE] [--progress json] [--set PATH=VALUE]\n"
     "           [--atlas[=CxR]] [--padding N] [--extrude N] [--crop]\n"
     "           [--atlas-pot] [--atlas-json hash|array]\n"
     "           [--preview OUT.webp|OUT.mp4] [--preview-quality Q]\n"
     "           [--format png|exr] [-q]\n"
     "           [--motion-vectors [--mv-max PIXELS] [--mv-flip-y]]\n"
     "           [--slice I/N | --slice-env VAR --slice-count N]",
     "render to DIR/<name>_0000.png, ... (several FILEs: DIR/<name>/...)", pfx_cmd_render},
    {"bake", CMD_BAKE,
     "pfx bake FILE -o OUT [--format csv|ply|pcache] [--every N] [--frames A:B[:S]]\n"
     "           [--fps N] [--seed N] [--max-particles N] [--max-memory SIZE]\n"
     "           [--threads N] [--force] [--depfile FILE] [--set PATH=VALUE]",
     "write the particle state of every output frame: CSV, PLY or pcache", pfx_cmd_bake},
    {"info", CMD_INFO,
     "pfx info FILE [--format text|json] [--seed N] [--max-particles N]\n"
     "           [--max-memory SIZE] [--threads N] [--motion-vectors]\n"
     "           [--set PATH=VALUE]",
     "show what the compiled effect holds", pfx_cmd_info},
    {"bench", CMD_BENCH,
     "pfx bench [SECTION...] [--json] [--renderer R]\n"
     "pfx bench accuracy -o DIR",
     "measure simulation and rendering speed (or integrator accuracy)", pfx_cmd_bench},
    {"assemble", CMD_ASSEMBLE,
     "pfx assemble DIR... -o OUT [--atlas[=CxR]] [--preview OUT.webp|OUT.mp4]\n"
     "           [--preview-quality Q]",
     "gather the frames of slices (--slice) into OUT, checking each", pfx_cmd_assemble},
    {"watch", CMD_WATCH | CMD_RENDER, "pfx watch FILE... -o DIR [render options]",
     "render, then render again on every save (unchanged files skipped)", pfx_cmd_watch},
    {"preview", CMD_PREVIEW,
     "pfx preview FILE [--port N] [--host ADDR] [--size WxH] [--seed N] [--no-open]\n"
     "           [--max-memory SIZE] [--renderer R] [--alpha MODE] [--set PATH=VALUE]\n"
     "           [--compare FILE]",
     "serve a live view of FILE to a browser, re-rendered on every save", pfx_cmd_preview},
    {"tune", CMD_TUNE,
     "pfx tune FILE -o DIR [--tolerance 0.5px|1mm] [--frames A:B]\n"
     "           [--set PATH=VALUE]",
     "chart speed against screen error; recommend the cheapest setting", pfx_cmd_tune},
    {"lsp", CMD_LSP, "pfx lsp",
     "serve the Language Server Protocol on stdin and stdout (for editors)", pfx_cmd_lsp},
    {"schema", CMD_SCHEMA, "pfx schema", "print the JSON Schema of the effect format",
     pfx_cmd_schema},
};
enum { COMMAND_COUNT = sizeof commands / sizeof commands[0] };

/* `text`'s lines, the first after `first`, the others after `rest`. */
static void print_lines(const char *first, const char *rest, const char *text) {
    const char *lead = first;
    for (const char *line = text; *line;) {
        size_t n = strcspn(line, "\n");
        printf("%s%.*s\n", lead, (int)n, line);
        lead = rest;
        line += n + (line[n] == '\n');
    }
}

/* The help on stdout: `pfx --help` (cmd NULL or not a command) gives every
 * command's usage, the commands and every option; `pfx COMMAND --help` its
 * own usage and the options it takes, from the same rows. */
static void print_help(const char *cmd) {
    const command_row *only = NULL;
    for (size_t i = 0; cmd && i < COMMAND_COUNT; i++)
        if (!strcmp(cmd, commands[i].name))
            only = &commands[i];
    for (size_t i = 0; i < COMMAND_COUNT; i++)
        if (!only || only == &commands[i])
            print_lines(i == 0 || only ? "usage: " : "       ", "       ", commands[i].usage);
    if (only) {
        printf("\n%s\n", only->summary);
    } else {
        fputs("\ncommands:\n", stdout);
        for (size_t i = 0; i < COMMAND_COUNT; i++)
            printf("  %-10s %s\n", commands[i].name, commands[i].summary);
    }
    fputs("\noptions:\n", stdout);
    for (int i = 0; i < OPTION_ROW_COUNT; i++) {
        const option_row *r = &option_rows[i];
        if (only && !(r->commands & only->bit))
            continue;
        char lead[64];
        snprintf(lead, sizeof lead, "  %-22s  ", r->shown);
        print_lines(lead, "                          ", r->help);
    }
}

/* The defaults a command line starts from; PFX_THREADS sets --threads'
 * default. Returns -1, or the exit status of a usage error. */
static int option_defaults(pfx_cli *o) {
    unsigned long long v;
    memset(o, 0, sizeof *o);
    /* PFX_THREADS, then --threads over it; neither: the machine's cores. */
    const char *threads = getenv("PFX_THREADS");
    if (threads && *threads) {
        if (!parse_ulong(threads, &v) || v < 1 || v > 1024)
            return pfx_cli_usage_error("PFX_THREADS takes a number from 1 to 1024, got '%s'",
                                       threads);
        o->compile.threads = (int)v;
    }
    o->last = -1;
    o->atlas_layout.padding = 2;
    o->atlas_layout.extrude = 1;
    o->preview_quality = -1;
    o->every = 1;
    o->max_memory = pfx_memory_default_bound();
    return -1;
}

/* One option getopt found (its value in optarg), into o. Returns -1, or
 * the exit status of a usage error. A flat switch, one case an option. */
static int parse_option(int c, int argc, char **argv, pfx_cli *o) {
    unsigned long long v;
    switch (c) {
    case 'o':
        o->output = optarg;
        break;
    case 'q':
        o->quiet = true;
        break;
    case 'j':
        if (!parse_ulong(optarg, &v) || v < 1 || v > 256)
            return pfx_cli_usage_error("-j takes a number of threads from 1 to 256, got '%s'",
                                       optarg);
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
        if (grid && (!parse_size(grid, &c, &r, &extra) || c < 1 || r < 1 || c > 16384 || r > 16384))
            return pfx_cli_usage_error("--atlas takes COLSxROWS, such as 8x8, got '%s'", grid);
        o->atlas = true;
        o->atlas_layout.columns = (int)c;
        o->atlas_layout.rows = (int)r;
        break;
    }
    case OPT_PADDING:
    case OPT_EXTRUDE:
        if (!parse_ulong(optarg, &v) || v > 256)
            return pfx_cli_usage_error(c == OPT_PADDING
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
            return pfx_cli_usage_error("--preview writes an animated WebP or an MP4: give a path "
                                       "ending in '.webp' or '.mp4', got '%s'",
                                       optarg);
        o->preview = optarg;
        break;
    }
    case OPT_CROP:
        o->atlas_layout.crop = true;
        break;
    case OPT_ATLAS_POT:
        o->atlas_layout.pot = true;
        break;
    case OPT_ATLAS_JSON:
        if (strcmp(optarg, "hash") && strcmp(optarg, "array"))
            return pfx_cli_usage_error("--atlas-json takes 'hash' or 'array', got '%s'", optarg);
        o->atlas_layout.json_array = !strcmp(optarg, "array");
        break;
    case OPT_PREVIEW_Q:
        if (!parse_ulong(optarg, &v) || v > 100)
            return pfx_cli_usage_error("--preview-quality takes a number from 0 to 100, got '%s'",
                                       optarg);
        o->preview_quality = (int)v;
        break;
    case OPT_MOTION_VECTORS:
        o->motion_vectors = true;
        break;
    case OPT_MV_MAX: {
        char *end;
        double px = strtod(optarg, &end);
        if (*end || !(px > 0 && px <= 1e6))
            return pfx_cli_usage_error("--mv-max takes pixels in (0, 1000000], got '%s'", optarg);
        o->mv_max = px;
        break;
    }
    case OPT_MV_FLIP_Y:
        o->mv_flip_y = true;
        break;
    case OPT_TOLERANCE:
        o->tolerance = optarg;
        break;
    case OPT_WERROR:
        o->werror = true;
        break;
    case OPT_LIST_RULES:
        o->list_rules = true;
        break;
    case OPT_PROGRESS:
        if (strcmp(optarg, "json"))
            return pfx_cli_usage_error("--progress takes 'json', got '%s'", optarg);
        o->progress_json = true;
        break;
    case 'h':
        print_help(argv[1]);
        return 0;
    case OPT_FRAMES:
        if (!parse_frames(optarg, o))
            return pfx_cli_usage_error(
                "--frames takes N, A:B or A: (to the end), then :S for every S-th frame, with "
                "0 <= A <= B <= 100000000 and S >= 1, got '%s'",
                optarg);
        break;
    case OPT_SIZE: {
        unsigned w, h;
        char extra;
        if (!parse_size(optarg, &w, &h, &extra) || w < 1 || h < 1 || w > 16384 || h > 16384)
            return pfx_cli_usage_error("--size takes WxH with each side from 1 to 16384, got '%s'",
                                       optarg);
        if ((unsigned long long)w * h > PFX_MAX_IMAGE_PIXELS)
            return pfx_cli_usage_error(
                "--size takes at most 134217728 pixels (the renderer's float "
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
            return pfx_cli_usage_error("--fps takes a number in (0, 1000], got '%s'", optarg);
        o->compile.fps = fps;
        break;
    }
    case OPT_SEED:
        if (!parse_ulong(optarg, &v))
            return pfx_cli_usage_error("--seed takes a whole number, got '%s'", optarg);
        o->compile.seed = v;
        o->compile.has_seed = true;
        break;
    case OPT_MAX:
        if (!parse_ulong(optarg, &v) || v < 1 || v > 100000000)
            return pfx_cli_usage_error(
                "--max-particles takes a number from 1 to 100000000, got '%s'", optarg);
        o->compile.max_particles = v;
        break;
    case OPT_EVERY:
        if (!parse_ulong(optarg, &v) || v < 1 || v > 1000000)
            return pfx_cli_usage_error("--every takes a whole number from 1, got '%s'", optarg);
        o->every = (long)v;
        break;
    case OPT_FORMAT:
        /* Each command reads its own words (validate: text, json, sarif; bake:
         * csv, ply, pcache); see format_of. */
        if (!pfx_frame_format_parse(optarg, &o->frames_as))
            o->format = optarg;
        else if (strcmp(argv[1], "render") && strcmp(argv[1], "watch"))
            return pfx_cli_usage_error("--format %s is for render's frames", optarg);
        break;
    case OPT_RENDERER:
        if (!pfx_cli_parse_renderer("--renderer", optarg, &o->renderer))
            return EXIT_USAGE;
        o->has_renderer = true;
        break;
    case OPT_ALPHA: {
        int mode = pfx_kind_find(pfx_alpha_mode_names, optarg);
        if (mode < 0)
            return pfx_cli_usage_error("--alpha takes 'straight' or 'premultiplied', got '%s'",
                                       optarg);
        o->compile.alpha = (pfx_alpha_mode)mode;
        o->compile.has_alpha = true;
        break;
    }
    case OPT_MAX_MEMORY:
        if (!pfx_memory_parse(optarg, &o->max_memory))
            return pfx_cli_usage_error("--max-memory takes a size in bytes, or with K, M, G or T "
                                       "after it, got '%s'",
                                       optarg);
        break;
    case OPT_THREADS:
        if (!parse_ulong(optarg, &v) || v < 1 || v > 1024)
            return pfx_cli_usage_error("--threads takes a number from 1 to 1024, got '%s'", optarg);
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
            return pfx_cli_usage_error("--slice takes I/N with 0 <= I < N <= 1000000, got '%s'",
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
            return pfx_cli_usage_error("--slice-count takes a number from 1 to 1000000, got '%s'",
                                       optarg);
        o->slice_count = (long)v;
        break;
    case OPT_SET: {
        /* The words stay in argv; the path is checked against the effect
         * when it loads (jobs/overrides.c). */
        static const char *sets[PFX_MAX_SETS];
        if (!strchr(optarg, '=') || optarg[0] == '=')
            return pfx_cli_usage_error("--set takes PATH=VALUE, such as emitters.flame.rate=300, "
                                       "got '%s'",
                                       optarg);
        if (o->compile.set_count == PFX_MAX_SETS)
            return pfx_cli_usage_error("at most 256 --set may be given, got '%s' past them",
                                       optarg);
        sets[o->compile.set_count++] = optarg;
        o->compile.sets = sets;
        break;
    }
    case OPT_PORT:
        if (!parse_ulong(optarg, &v) || v > 65535)
            return pfx_cli_usage_error("--port takes a number from 0 to 65535, got '%s'", optarg);
        o->port = (unsigned)v;
        break;
    case OPT_HOST:
        o->host = optarg;
        break;
    case OPT_NO_OPEN:
        o->no_open = true;
        break;
    case OPT_COMPARE:
        o->compare = optarg;
        break;
    case ':':
        return pfx_cli_usage_error("option '%s' needs a value", option_word(argv, optopt));
    default:
        return pfx_cli_usage_error("unknown option '%s'", option_word(argv, optopt));
    }
    return -1;
}

/* --slice-env VAR --slice-count N: the slice index from the environment,
 * resolved now so that every later step sees one slice. Returns -1, or the
 * exit status of a usage error. */
static int resolve_slice_env(pfx_cli *o) {
    if (o->slice_env) {
        if (!o->slice_count)
            return pfx_cli_usage_error("%s", "--slice-env needs --slice-count N");
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
        return pfx_cli_usage_error("%s", "--slice-count goes with --slice-env VAR");
    }
    return -1;
}

/* What no single option can check: --slice-env resolved now, the
 * combinations each command refuses, and --format's word for the
 * command. Returns -1, or the exit status of a usage error. */
static int check_options(int argc, char **argv, pfx_cli *o) {
    int stop = resolve_slice_env(o);
    if (stop >= 0)
        return stop;
    if (o->preview && o->slices)
        return pfx_cli_usage_error("%s",
                                   "--preview needs every frame: give it to 'pfx assemble' instead "
                                   "of the slices");
    if (o->preview && argc - optind > 1 && strcmp(argv[1], "render") == 0) {
        int files = 0;
        for (int i = optind; i < argc; i++)
            files += argv[i][0] != '-';
        if (files > 1)
            return pfx_cli_usage_error("%s", "--preview names one file: give one FILE");
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
        return pfx_cli_usage_error("%s",
                                   "--atlas needs every frame: give it to 'pfx assemble' instead "
                                   "of the slices");
    if (o->preview_quality >= 0 && !o->preview)
        return pfx_cli_usage_error("%s", "--preview-quality goes with --preview");
    if ((o->mv_max > 0 || o->mv_flip_y) && !o->motion_vectors)
        return pfx_cli_usage_error("%s", "--mv-max and --mv-flip-y go with --motion-vectors");
    if (o->motion_vectors && strcmp(argv[1], "render") && strcmp(argv[1], "info"))
        return pfx_cli_usage_error("%s", "--motion-vectors is for render (and info's estimate)");
    if (o->frames_as == PFX_FRAME_EXR) {
        /* EXR keeps the float image; what needs 8-bit frames cannot follow. */
        if (o->atlas || o->preview)
            return pfx_cli_usage_error("%s cannot go with --format exr: it is built from 8-bit PNG "
                                       "frames; render PNG frames for it",
                                       o->atlas ? "--atlas" : "--preview");
        if (o->compile.has_alpha && o->compile.alpha == PFX_ALPHA_STRAIGHT)
            return pfx_cli_usage_error("%s",
                                       "--alpha straight cannot go with --format exr: EXR alpha "
                                       "is premultiplied by definition");
    }
    /* --frames A:B:S and bake's --every N say the same thing. */
    if (o->every > 1 && strcmp(argv[1], "bake"))
        return pfx_cli_usage_error("%s", "--every is for bake; other commands take every S-th "
                                         "frame with --frames A:B:S");
    if (o->frames_step) {
        if (o->every > 1 && o->every != o->frames_step)
            return pfx_cli_usage_error("%s", "--every N and --frames A:B:S both choose every "
                                             "S-th frame, and disagree: give one");
        o->every = o->frames_step;
    }
    /* A sheet or a preview of every S-th frame plays at fps / S; motion
     * vectors are the motion to the next frame, which a step leaves out. */
    if (o->every > 1 && !strcmp(argv[1], "render") && o->motion_vectors)
        return pfx_cli_usage_error("%s", "--motion-vectors cannot go with a --frames step: they "
                                         "are the motion to the next frame");
    if (o->slices && strcmp(argv[1], "render"))
        return pfx_cli_usage_error("%s", "--slice and --slice-env are for render");
    /* --format: the diagnostics' form for every command but bake, whose
     * word names the cache format (read in cmd_bake). */
    if (o->format && strcmp(argv[1], "bake")) {
        bool validate = !strcmp(argv[1], "validate");
        o->sarif = validate && !strcmp(o->format, "sarif");
        if (strcmp(o->format, "text") && strcmp(o->format, "json") && !o->sarif)
            return pfx_cli_usage_error(
                validate ? "--format takes 'text', 'json' or 'sarif', got '%s'"
                : strcmp(argv[1], "render")
                    ? "--format takes 'text' or 'json', got '%s'"
                    : "--format takes 'text' or 'json' (diagnostics), or 'png' or "
                      "'exr' (frames), got '%s'",
                o->format);
        o->json = !strcmp(o->format, "json");
    }
    if (o->compile.set_count &&
        (!strcmp(argv[1], "bench") || !strcmp(argv[1], "assemble") || !strcmp(argv[1], "schema")))
        return pfx_cli_usage_error("--set is for a command that reads an effect, not %s", argv[1]);
    if ((o->port || o->host || o->no_open || o->compare) && strcmp(argv[1], "preview"))
        return pfx_cli_usage_error("%s", "--port, --host, --no-open and --compare are for preview");
    if (o->list_rules && strcmp(argv[1], "validate"))
        return pfx_cli_usage_error("%s", "--list-rules is for validate");
    return -1;
}

/* Parses the options after the command; returns -1 on success or the exit
 * status to stop with. Positional arguments are left in argv[optind..]. */
static int parse_options(int argc, char **argv, pfx_cli *o) {
    int stop = option_defaults(o);
    if (stop >= 0)
        return stop;
    opterr = 0;
    optind = 2; /* argv[1] is the command */
    int c;
    while ((c = getopt_long(argc, argv, shortopts, longopts, NULL)) != -1)
        if ((stop = parse_option(c, argc, argv, o)) >= 0)
            return stop;
    return check_options(argc, argv, o);
}

/* The row of the command named `name`, or COMMAND_COUNT. */
static size_t find_command(const char *name) {
    for (size_t i = 0; i < COMMAND_COUNT; i++)
        if (!strcmp(name, commands[i].name))
            return i;
    return COMMAND_COUNT;
}

/* A word that names no command: a usage error, with the nearest name. */
static int unknown_command(const char *cmd) {
    const char *names[COMMAND_COUNT + 1] = {NULL};
    for (size_t i = 0; i < COMMAND_COUNT; i++)
        names[i] = commands[i].name;
    const char *sug = pfx_suggest(cmd, names);
    if (sug) {
        fprintf(stderr, "pfx: unknown command '%s'; did you mean '%s'?\n", cmd, sug);
        fputs("Try 'pfx --help' for more information.\n", stderr);
        return EXIT_USAGE;
    }
    return pfx_cli_usage_error("unknown command '%s'", cmd);
}

int main(int argc, char **argv) {
    /* Before any thread starts: a signal removes the temporary files. */
    pfx_atomic_guard_signals();
    if (argc < 2)
        return pfx_cli_usage_error("%s", "no command given");
    const char *cmd = argv[1];
    make_getopt_tables();
    if (!strcmp(cmd, "-h") || !strcmp(cmd, "--help") || !strcmp(cmd, "help")) {
        /* pfx help COMMAND: that command's help, as pfx COMMAND --help. */
        if (argc > 2 && find_command(argv[2]) == COMMAND_COUNT)
            return unknown_command(argv[2]);
        print_help(argc > 2 ? argv[2] : NULL);
        return 0;
    }
    if (!strcmp(cmd, "--version")) {
        puts("pfx " PFX_VERSION);
        return 0;
    }
    /* The command first: a mistyped one is named as such, not blamed on
     * an option that only some commands take. */
    size_t which = find_command(cmd);
    if (which == COMMAND_COUNT)
        return unknown_command(cmd);
    pfx_cli o;
    int stop = parse_options(argc, argv, &o);
    if (stop >= 0)
        return stop;
    return commands[which].run((const char *const *)argv + optind, argc - optind, &o);
}
