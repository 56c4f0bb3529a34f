/* The compiler's state and the passes of pfx_compile that live in their
 * own files (an emitter, the seamless loop, the pools). Internal to
 * src/compile. */
#ifndef PFX_COMPILE_COMPILER_H
#define PFX_COMPILE_COMPILER_H

#include "compile/compile.h"
#include "compile/keys.h"
#include "compile/read.h"

/* Bounds that keep any file's cost finite; each is documented in
 * man/pfx-effect.5. */
#define MAX_IMAGE_SIDE PFX_MAX_IMAGE_SIDE
#define MAX_SIM_RATE 100000.0
#define MAX_SECONDS 86400.0
#define MAX_FPS PFX_MAX_FPS
#define MAX_FRAMES 1000000.0
#define MAX_STEPS 1e8

typedef struct compiler {
    pfx_reader r;
    pfx_effect *e;
    const pfx_compile_options *opt;
} compiler;

/* Emitter `key: n` into em (compile/emitter.c). */
void pfx_compile_emitter(compiler *c, const pfx_node *key, const pfx_node *n, pfx_emitter *em);
/* The tables of the top level, sim, camera, image and an emitter, for the
 * schema. */
extern const pfx_key_table pfx_schema_top, pfx_sim_table, pfx_camera_table, pfx_image_table,
    pfx_emitter_table;

/* The seamless loop: periods, warm-up and the warnings for what cannot
 * repeat (compile/loop.c). */
void pfx_compile_loop(compiler *c, const pfx_node *root, const pfx_node *loop,
                      const pfx_node *emitters);

/* The effect's `allow:` table of acknowledged warnings, into the file's
 * diagnostics (compile/allow.c). */
void pfx_compile_allow(compiler *c, const pfx_node *allow);

/* Each emitter's pool from its worst case, within the particle budget
 * (compile/pools.c). */
void pfx_size_pools(compiler *c, const pfx_node *emitters);

#endif
