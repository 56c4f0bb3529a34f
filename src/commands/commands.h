/* The commands of pfx (validate, render, bake, info, assemble, schema,
 * bench): what each does with the options main.c parsed from argv and the
 * FILE or DIR operands that followed them. One file a command; this header
 * holds the parsed options and the helpers the commands share
 * (commands/common.c). Each returns the process's exit status; nothing
 * below main.c exits. */
#ifndef PFX_COMMANDS_H
#define PFX_COMMANDS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "compile/compile.h"
#include "jobs/delivery.h"
#include "jobs/load.h"
#include "jobs/output_names.h"
#include "output/atlas.h"
#include "output/frame_queue.h"
#include "render/render.h"

/* Exit status: 0 success, 1 invalid input or I/O failure, 2 usage error. */
#define EXIT_INVALID 1
#define EXIT_USAGE 2

/* The options of a command line, as main.c parsed them. */
typedef struct pfx_cli {
    const char *output;
    long first, last; /* --frames; last < 0: to the end */
    bool has_frames;
    long frames_step;   /* --frames A:B:S's S; 0: none given */
    const char *format; /* --format, as given; NULL: the command's default */
    bool json;          /* diagnostics as JSON lines (validate --format json) */
    bool sarif;         /* validate --format sarif: one SARIF log on stdout */
    bool list_rules;    /* validate --list-rules */
    bool bench_json;    /* bench --json */
    bool quiet;
    long every; /* every Nth frame from the first (1: all): --every N or --frames A:B:N */
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
    int preview_quality;           /* --preview-quality 0..100; -1: not given */
    bool motion_vectors;           /* --motion-vectors */
    double mv_max;                 /* --mv-max PIXELS; 0: the sequence's largest */
    bool mv_flip_y;                /* --mv-flip-y */
    pfx_frame_format frames_as;    /* render --format png|exr */
    unsigned port;                 /* preview --port N; 0: a free one */
    const char *host;              /* preview --host ADDR; NULL: 127.0.0.1 */
    bool no_open;                  /* preview --no-open */
    const char *tolerance;         /* tune --tolerance, as given (0.5px, 1mm) */
    const char *compare;           /* preview --compare FILE: A/B against it */
    pfx_compile_options compile;
} pfx_cli;

/* The commands: `operands` are the words after the options (the effect
 * files, or assemble's directories), `count` of them. */
int pfx_cmd_validate(const char *const *operands, int count, const pfx_cli *o);
int pfx_cmd_schema(const char *const *operands, int count, const pfx_cli *o);
int pfx_cmd_render(const char *const *operands, int count, const pfx_cli *o);
int pfx_cmd_bake(const char *const *operands, int count, const pfx_cli *o);
int pfx_cmd_info(const char *const *operands, int count, const pfx_cli *o);
int pfx_cmd_assemble(const char *const *operands, int count, const pfx_cli *o);
int pfx_cmd_bench(const char *const *operands, int count, const pfx_cli *o);
int pfx_cmd_preview(const char *const *operands, int count, const pfx_cli *o);
int pfx_cmd_watch(const char *const *operands, int count, const pfx_cli *o);
int pfx_cmd_lsp(const char *const *operands, int count, const pfx_cli *o);
int pfx_cmd_tune(const char *const *operands, int count, const pfx_cli *o);

/* pfx render for a front end that renders again and again (`pfx watch`):
 * loaded(ctx, e) hears of each file's compiled effect (one that compiles,
 * --werror's warnings or not) before it renders, so that what the file
 * reads is known from the one load. pfx_cmd_render passes NULL. */
typedef void (*pfx_cli_loaded_fn)(void *ctx, const pfx_effect *e);
int pfx_cli_render_each(const char *const *operands, int count, const pfx_cli *o,
                        pfx_cli_loaded_fn loaded, void *ctx);

/* Shared by the commands (commands/common.c). */
/* Looks up a renderer name; on a bad one prints the usage error, naming
 * `what` (the option or variable) and every kind, and returns false. */
bool pfx_cli_parse_renderer(const char *what, const char *name, pfx_renderer_kind *kind);
int pfx_cli_usage_error(const char *fmt, const char *arg);
/* The renderer for render and bench: --renderer, else PFX_RENDERER, else
 * auto. Returns false (after the usage error) on a bad PFX_RENDERER. */
bool pfx_cli_renderer_kind(const pfx_cli *o, pfx_renderer_kind *kind);
/* --werror: true (with a line saying so) when l has warnings to fail on. */
bool pfx_cli_fails_on_warnings(const pfx_loaded *l, const char *path, const pfx_cli *o);
/* Loads and compiles one file, printing its diagnostics. With --werror a
 * warning fails it: the effect stays in l (freed with it), unused. */
pfx_effect *pfx_cli_load(pfx_loaded *l, const char *path, const pfx_cli *o);
/* mkdir -p */
bool pfx_cli_make_dirs(const char *path, pfx_diags *d);
/* mkdir -p of the directory part of a file path. */
bool pfx_cli_make_parent_dirs(const char *path, pfx_diags *d);
/* The file's name without directory and extension: out/fire_0000.png. */
void pfx_cli_file_stem(const char *path, char *out, size_t size);
/* Resolves --frames against the effect's frame count; false if outside.
 * With a step (o->every > 1), *last is the last frame the step reaches. */
bool pfx_cli_frame_range(const pfx_effect *e, const pfx_cli *o, long *first, long *last);
/* The frames first, first + o->every, ... up to last: how many. */
long pfx_cli_frame_count(const pfx_cli *o, long first, long last);
/* Refuses, before anything is allocated, a run estimated to need more than
 * --max-memory (default half of physical memory), naming the biggest part. */
bool pfx_cli_memory_fits(const pfx_effect *e, long first, long last, bool render, const pfx_cli *o,
                         pfx_diags *run);
/* The manifest's settings common to render and bake (the effect's values
 * after --fps, --size, --seed and --max-particles, and --set), and its
 * inputs (the effect hashed as the bytes l parsed). */
bool pfx_cli_describe_run(pfx_delivery *dl, const pfx_loaded *l, long first, long last,
                          const pfx_cli *o, pfx_diags *d);
/* Adds dl's manifest and depfile to names, and checks every name before
 * any work: each fits its directory, none is an input of dl->now, and the
 * depfile can name every input. False with the reasons in d. */
bool pfx_cli_check_outputs(const pfx_delivery *dl, pfx_output_names *names, pfx_diags *d);
/* Says that there was nothing to do, with the key that proved it. */
void pfx_cli_say_up_to_date(const pfx_cli *o, const char *path, const char *where,
                            pfx_delivery *dl);

#endif
