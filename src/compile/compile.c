/* pfx_compile: the effect format's top level (its key table and those of
 * sim, camera and image), then the forces, deflectors and emitters, each
 * in its own file, and the passes over the whole effect (loop, pools). It
 * reports every problem it finds (not only the first) and fills a
 * pfx_effect in the caller's arena, so the simulation only reads. */
#include "compile/compile.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compile/compile_deflectors.h"
#include "compile/compile_forces.h"
#include "compile/compile_look.h"
#include "compile/compile_spawn.h"
#include "compile/compiler.h"

#define E(field) offsetof(pfx_effect, field)
#define C(field) offsetof(pfx_camera, field)

/* ---- sim ---- */

/* sim.tolerance: m per simulated second as a number, or a screen error as
 * "0.5px" (kept in pixels; the emitters convert it at their depth). */
static void read_tolerance(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map;
    pfx_effect *e = dest;
    if (v->kind == PFX_NODE_SCALAR && v->len > 2 && !strcmp(v->text + v->len - 2, "px")) {
        char buf[64], *end;
        snprintf(buf, sizeof buf, "%.*s", (int)(v->len - 2), v->text);
        double px = strtod(buf, &end);
        if (end == buf || *end || !(px > 0 && px <= 1e6))
            pfx_read_error(r, v, PFX_RULE_OUT_OF_RANGE,
                           "'tolerance' in pixels must be a number above 0 and at most 1e6 "
                           "before 'px', got '%s'",
                           v->text);
        else
            e->tolerance_px = px;
        return;
    }
    double t;
    if (v->kind == PFX_NODE_SCALAR && !v->plain) {
        pfx_read_error(r, v, PFX_RULE_WRONG_TYPE,
                       "'tolerance' must be a number of m/s or pixels such as '0.5px', got '%s'",
                       v->text);
        return;
    }
    if (v->kind == PFX_NODE_SCALAR) {
        char *end;
        strtod(v->text, &end);
        if (end == v->text || *end) {
            pfx_read_error(r, v, PFX_RULE_WRONG_TYPE,
                           "'tolerance' must be a number of m/s or pixels such as '0.5px', got "
                           "'%s'",
                           v->text);
            return;
        }
    }
    if (!pfx_read_number(r, v, "tolerance", &t))
        return;
    if (pfx_check_above(r, v, "tolerance", t, 1e-12, false) &&
        pfx_check_below(r, v, "tolerance", t, 1e6, false))
        e->tolerance = t;
}

static const pfx_key sim_keys[] = {
    {"rate", PFX_KEY_NUMBER, .lo = 1, .hi = MAX_SIM_RATE, .def = {120}, .offset = E(sim_rate),
     .doc = "Fixed simulation steps per second, 1 to 100000."},
    {"prewarm", PFX_KEY_NUMBER, .lo = 0, .hi = MAX_SECONDS, .offset = E(prewarm),
     .doc = "Seconds simulated before frame 0, 0 to 86400."},
    {"integrator", PFX_KEY_ENUM, .offset = E(integrator), .names = pfx_integrator_names,
     .what = "integrator",
     .doc = "The integrator: auto (default: chosen per emitter from the forces it feels), euler, "
            "symplectic, midpoint, rk4, verlet, exact (closed form / split step) or boris (split "
            "step with the Boris rotation)."},
    {"tolerance", PFX_KEY_NUMBER, .lo = 1e-12, .hi = 1e6, .def = {1e-3}, .offset = E(tolerance),
     .hook = read_tolerance,
     .schema = "{\"oneOf\": [{\"type\": \"number\", \"minimum\": 1e-12, \"maximum\": 1e6}, "
               "{\"type\": \"string\", \"pattern\": "
               "\"^[0-9]*\\\\.?[0-9]+([eE][-+]?[0-9]+)?px$\"}], \"default\": 0.001}",
     .doc = "For auto: the position error allowed, metres per simulated second (1e-12 to 1e6), "
            "or on screen in pixels ('0.5px', above 0, at most 1e6): at each emitter's depth "
            "through the camera, spread over its longest lifetime."},
    {"substeps", PFX_KEY_WHOLE, PFX_KEY_NO_DEFAULT, .lo = 1, .hi = PFX_MOTION_MAX_SUBSTEPS,
     .offset = E(substeps),
     .doc = "Substeps per step, 1 to 1024, for every emitter with a motion model (default: auto "
            "chooses, others 1)."},
};
PFX_KEY_TABLE(pfx_sim_table, "sim", NULL, "The fixed-step simulation.", sim_keys);

/* ---- camera ---- */

/* fov or ortho, not both; ortho switches the projection. */
static void read_fov(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    pfx_camera *k = dest;
    if (pfx_node_get(map, "ortho"))
        return; /* reported at 'ortho' */
    double deg;
    if (!pfx_read_number(r, v, "fov", &deg))
        return;
    if (!(deg > 0 && deg < 180))
        pfx_read_error(r, v, PFX_RULE_OUT_OF_RANGE,
                       "'fov' must be between 0 and 180 degrees (exclusive), got %g", deg);
    k->fov = deg * PFX_DEGREE;
}

static void read_ortho(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    pfx_camera *k = dest;
    if (pfx_node_get(map, "fov")) {
        pfx_read_error(r, v, PFX_RULE_CONFLICTING_KEYS,
                       "'camera' takes either 'fov' or 'ortho', not both");
        return;
    }
    if (pfx_read_number(r, v, "ortho", &k->ortho_height)) {
        k->ortho = true;
        pfx_check_above(r, v, "ortho", k->ortho_height, 0, true);
    }
}

static const pfx_key camera_keys[] = {
    {"position", PFX_KEY_VEC3, .def = {0, 1, 6}, .offset = C(position),
     .doc = "Where the camera is, metres."},
    {"target", PFX_KEY_VEC3, .def = {0, 1, 0}, .offset = C(target),
     .doc = "The point it looks at; not the position."},
    {"up", PFX_KEY_VEC3, .def = {0, 1, 0}, .offset = C(up),
     .doc = "Up in the picture; not parallel to the view direction."},
    {"fov", PFX_KEY_NUMBER, PFX_KEY_LO_STRICT | PFX_KEY_HI_STRICT | PFX_KEY_DEGREES, .lo = 0,
     .hi = 180, .def = {40}, .offset = C(fov), .hook = read_fov,
     .doc = "Vertical field of view in degrees, between 0 and 180 (exclusive)."},
    {"ortho", PFX_KEY_NUMBER, PFX_KEY_LO_STRICT | PFX_KEY_NO_DEFAULT, .lo = 0, .hi = INFINITY,
     .offset = -1, .hook = read_ortho,
     .doc = "Orthographic view height in metres, greater than 0 (instead of fov)."},
};
PFX_KEY_TABLE_EXTRA(pfx_camera_table, "camera", NULL,
                    "The camera: perspective (fov) or orthographic (ortho), not both.", camera_keys,
                    "{\"not\": {\"required\": [\"fov\", \"ortho\"]}}");

/* Whether an optional vector key was absent or three finite numbers (the
 * row has reported it otherwise). */
static bool vec3_read(const pfx_node *n) {
    if (!n)
        return true;
    if (n->kind != PFX_NODE_SEQ || n->count != 3)
        return false;
    for (size_t i = 0; i < 3; i++) {
        char *end;
        const pfx_node *x = n->items[i];
        if (x->kind != PFX_NODE_SCALAR || !isfinite(strtod(x->text, &end)) || *end)
            return false;
    }
    return true;
}

static void compile_camera(compiler *c, const pfx_node *cam) {
    pfx_camera *k = &c->e->camera;
    if (!pfx_read_map(&c->r, cam, "camera"))
        return;
    pfx_keys_check(&c->r, cam, &pfx_camera_table, "'camera'");
    pfx_keys_read(&c->r, cam, &pfx_camera_table, k);
    if (pfx_node_get(cam, "fov") && pfx_node_get(cam, "ortho"))
        return;
    /* The view is checked only when its three vectors were read. */
    bool ok = vec3_read(pfx_node_get(cam, "position")) && vec3_read(pfx_node_get(cam, "target")) &&
              vec3_read(pfx_node_get(cam, "up"));
    if (!ok)
        return;
    double side[3], up_axis[3], forward[3];
    const pfx_node *target = pfx_node_get(cam, "target"), *up = pfx_node_get(cam, "up");
    switch (pfx_camera_frame(k, side, up_axis, forward)) {
    case PFX_CAMERA_SAME_POINT:
        pfx_read_error(&c->r, target ? target : cam, PFX_RULE_INCONSISTENT_VALUES,
                       "camera 'position' and 'target' are the same point");
        break;
    case PFX_CAMERA_UP_PARALLEL:
        pfx_read_error(&c->r, up ? up : cam, PFX_RULE_INCONSISTENT_VALUES,
                       "camera 'up' is parallel to the view direction");
        break;
    case PFX_CAMERA_OK:
        break;
    }
}

/* ---- image ---- */

static void read_motion_blur(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map;
    pfx_compile_motion_blur(r, v, dest);
}

static void read_light(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map;
    pfx_compile_light(r, v, dest);
}

static void read_image_size(pfx_reader *r, const pfx_node *map, const pfx_node *size, void *dest) {
    (void)map;
    pfx_effect *e = dest;
    double wh[2];
    if (!pfx_read_numbers(r, size, "size", wh, 2))
        return;
    bool sides_ok = true;
    for (int i = 0; i < 2; i++) {
        const pfx_node *n = size->items[i];
        if (wh[i] != floor(wh[i]) || wh[i] < 1 || wh[i] > MAX_IMAGE_SIDE) {
            pfx_read_error(r, n, PFX_RULE_OUT_OF_RANGE,
                           "image 'size' must be whole numbers of pixels from 1 to %d, got %g",
                           MAX_IMAGE_SIDE, wh[i]);
            sides_ok = false;
        }
    }
    e->width = (int)fmin(fmax(wh[0], 1), MAX_IMAGE_SIDE);
    e->height = (int)fmin(fmax(wh[1], 1), MAX_IMAGE_SIDE);
    /* Each side in range, the two together may still be too many. */
    if (sides_ok && (double)e->width * e->height > (double)PFX_MAX_IMAGE_PIXELS)
        pfx_read_error(r, size, PFX_RULE_TOO_LARGE,
                       "image 'size' %dx%d has %.0f pixels; the renderer's float framebuffer "
                       "holds at most %llu (16 bytes a pixel, 2 GiB), such as 16384x8192",
                       e->width, e->height, (double)e->width * e->height,
                       (unsigned long long)PFX_MAX_IMAGE_PIXELS);
}

static const pfx_key image_keys[] = {
    {"size", PFX_KEY_CODE, .offset = -1, .hook = read_image_size,
     .schema = "{\"type\": \"array\", \"items\": {\"type\": \"integer\", \"minimum\": 1, "
               "\"maximum\": 16384}, \"minItems\": 2, \"maxItems\": 2, \"default\": [512, 512]}",
     .doc = "[width, height] in pixels, each 1 to 16384, at most 134217728 pixels in all "
            "(--size overrides)."},
    {"background", PFX_KEY_COLOUR, .offset = E(background),
     .schema = "{\"$ref\": \"#/$defs/colour\", \"default\": \"transparent\"}",
     .doc = "The colour the image is cleared to."},
    {"exposure", PFX_KEY_NUMBER, .lo = -20, .hi = 20, .def = {0}, .offset = E(exposure),
     .doc = "EV, -20 to 20: colours are multiplied by 2^exposure before the tone curve."},
    {"tonemap", PFX_KEY_ENUM, .names = pfx_tonemap_names, .def = {0}, .offset = E(tonemap),
     .what = "tone curve",
     .doc = "none (values above 1 clip), reinhard (x / (1 + x)) or aces (the ACES filmic fit of "
            "Narkowicz 2015)."},
    {"preserve_hue", PFX_KEY_NUMBER, .lo = 0, .hi = 1, .def = {0}, .offset = E(preserve_hue),
     .doc = "0 to 1: how far the tone curve keeps the hue of bright colours; 0 maps each channel "
            "by itself (bright colours go to white), 1 maps the brightest channel and scales the "
            "others with it (fire stays orange)."},
    {"alpha", PFX_KEY_ENUM, .names = pfx_alpha_mode_names, .def = {0}, .offset = E(alpha_mode),
     .what = "alpha mode",
     .doc = "straight (colour and coverage apart) or premultiplied (colour times coverage; "
            "additive light is colour with zero alpha); --alpha overrides."},
    {"dither", PFX_KEY_BOOL, .def = {1}, .offset = E(dither),
     .doc = "A fixed per-pixel dither of under half a step before 8-bit quantisation, so smooth "
            "gradients do not band; exact 0 and 1 stay exact."},
    {"motion_blur", PFX_KEY_CODE, .offset = -1, .hook = read_motion_blur,
     .schema = "{\"$ref\": \"#/$defs/motion_blur\"}",
     .doc = "Motion blur: {shutter, samples}; absent, none."},
};
PFX_KEY_TABLE(pfx_image_table, "image", NULL, "The output image.", image_keys);

/* ---- The top level ---- */

static void read_version(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map, (void)dest;
    double version;
    if (pfx_read_number(r, v, "pfx", &version) && version != PFX_FORMAT_VERSION)
        pfx_read_error(r, v, PFX_RULE_FORMAT_VERSION,
                       "unsupported format version '%s'; this pfx reads version %d", v->text,
                       PFX_FORMAT_VERSION);
}

static void read_seed(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map;
    pfx_read_uint(r, v, "seed", &((pfx_effect *)dest)->seed);
}

/* sim and image fill the effect itself; camera its camera. */
static void read_sim(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map;
    if (!pfx_read_map(r, v, "sim"))
        return;
    pfx_keys_check(r, v, &pfx_sim_table, "'sim'");
    pfx_keys_read(r, v, &pfx_sim_table, dest);
}

static void read_image(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map;
    if (!pfx_read_map(r, v, "image"))
        return;
    pfx_keys_check(r, v, &pfx_image_table, "'image'");
    pfx_keys_read(r, v, &pfx_image_table, dest);
}

static const pfx_key top_keys[] = {
    {"pfx", PFX_KEY_CODE, PFX_KEY_REQUIRED, .offset = -1, .hook = read_version,
     .schema = "{\"const\": 1}", .doc = "Format version; must be 1."},
    {"duration", PFX_KEY_NUMBER, PFX_KEY_LO_STRICT, .lo = 0, .hi = MAX_SECONDS, .def = {2},
     .offset = E(duration),
     .doc = "Seconds of output, greater than 0, at most 86400; round(duration x fps) frames, at "
            "most 1,000,000. The loop's period when loop is true."},
    {"fps", PFX_KEY_NUMBER, PFX_KEY_LO_STRICT, .lo = 0, .hi = MAX_FPS, .def = {30},
     .offset = E(fps),
     .doc = "Output frames per second, greater than 0, at most 1000 (--fps overrides)."},
    {"seed", PFX_KEY_WHOLE, .lo = 0, .hi = 18446744073709551615.0, .offset = -1, .hook = read_seed,
     .doc = "Random seed, 0 to 2^64 - 1 (--seed overrides)."},
    {"sim", PFX_KEY_MAP, .offset = -1, .table = &pfx_sim_table, .hook = read_sim,
     .doc = "The fixed-step simulation."},
    {"camera", PFX_KEY_MAP, .offset = -1, .table = &pfx_camera_table,
     .doc = "The camera: perspective (fov) or orthographic (ortho), not both."},
    {"image", PFX_KEY_MAP, .offset = -1, .table = &pfx_image_table, .hook = read_image,
     .doc = "The output image."},
    {"forces", PFX_KEY_CODE, .offset = -1,
     .schema = "{\"type\": \"object\", \"maxProperties\": 32, \"additionalProperties\": "
               "{\"$ref\": \"#/$defs/force\"}}",
     .doc = "Named forces (at most 32); every emitter feels all of them unless it lists its own."},
    {"deflectors", PFX_KEY_CODE, .offset = -1,
     .schema = "{\"type\": \"object\", \"maxProperties\": 64, \"additionalProperties\": "
               "{\"$ref\": \"#/$defs/deflector\"}}",
     .doc = "Named deflectors (at most 64); every emitter's particles hit all of them unless it "
            "lists its own."},
    {"emitters", PFX_KEY_CODE, .offset = -1,
     .schema = "{\"type\": \"object\", \"maxProperties\": 1024, \"additionalProperties\": "
               "{\"$ref\": \"#/$defs/emitter\"}}",
     .doc = "Named emitters (at most 1024), in file order (bake row order, draw order at equal "
            "depth)."},
    {"light", PFX_KEY_CODE, .offset = -1, .hook = read_light,
     .schema = "{\"$ref\": \"#/$defs/light\"}",
     .doc = "The directional light of emitters with lit: true."},
    {"allow", PFX_KEY_CODE, .offset = -1,
     .schema = "{\"type\": \"object\", \"additionalProperties\": {\"type\": \"string\", "
               "\"pattern\": \"\\\\S\"}}",
     .doc = "Warnings acknowledged, each rule id with the reason: {PFX5002: \"the splash counts "
            "differ per loop\"}. An allowed warning is not printed, does not fail --werror, and "
            "is a suppression in SARIF; only warning rules can be allowed."},
    {"loop", PFX_KEY_BOOL, .offset = E(loop),
     .doc = "A seamless loop: every emitter repeats with period duration, and frame duration x "
            "fps is frame 0."},
};
const pfx_key_table pfx_schema_top = {
    "effect",
    "A pfx particle effect file (YAML). Distances in metres, times in seconds, angles "
    "in degrees. See pfx-effect(5).",
    NULL,
    top_keys,
    sizeof top_keys / sizeof top_keys[0],
    NULL};

static void compile_forces(compiler *c, const pfx_node *forces) {
    if (!pfx_read_map(&c->r, forces, "forces"))
        return;
    if (forces->count > PFX_MAX_FORCES) {
        pfx_read_error(&c->r, forces, PFX_RULE_TOO_MANY, "an effect has at most %d forces, got %zu",
                       PFX_MAX_FORCES, forces->count);
        return;
    }
    c->e->forces = pfx_arena_alloc(c->r.arena, (forces->count + 1) * sizeof *c->e->forces);
    if (!c->e->forces)
        return;
    for (size_t i = 0; i < forces->count; i++)
        pfx_compile_force(&c->r, forces->pairs[i].key, forces->pairs[i].value, c->e->seed,
                          &c->e->forces[c->e->force_count++]);
}

static void compile_deflectors(compiler *c, const pfx_node *defl) {
    if (!pfx_read_map(&c->r, defl, "deflectors"))
        return;
    if (defl->count > PFX_MAX_DEFLECTORS) {
        pfx_read_error(&c->r, defl, PFX_RULE_TOO_MANY,
                       "an effect has at most %d deflectors, got %zu", PFX_MAX_DEFLECTORS,
                       defl->count);
        return;
    }
    c->e->deflectors = pfx_arena_alloc(c->r.arena, (defl->count + 1) * sizeof *c->e->deflectors);
    if (!c->e->deflectors)
        return;
    for (size_t i = 0; i < defl->count; i++)
        pfx_compile_deflector(&c->r, defl->pairs[i].key, defl->pairs[i].value, c->e->seed,
                              &c->e->deflectors[c->e->deflector_count++]);
}

/* The effect before its keys are read: the defaults of every row, then an
 * image of 512 x 512, and the settings only the command line gives. */
static void effect_defaults(pfx_effect *e, const char *path, const pfx_compile_options *opt) {
    e->path = path;
    pfx_keys_defaults(&pfx_schema_top, e);
    pfx_keys_defaults(&pfx_sim_table, e);
    pfx_keys_defaults(&pfx_camera_table, &e->camera);
    pfx_keys_defaults(&pfx_image_table, e);
    pfx_look_defaults(e);
    e->width = e->height = 512;
    e->max_particles = opt && opt->max_particles ? opt->max_particles : PFX_DEFAULT_MAX_PARTICLES;
    e->threads = opt ? opt->threads : 0;
}

/* The command line's overrides of output keys (--fps, --alpha, --size).
 * --seed is not here: it must reach the forces and deflectors, which take
 * their seeds from the effect's as they compile. */
static void apply_overrides(pfx_effect *e, const pfx_compile_options *opt) {
    if (opt && opt->fps > 0)
        e->fps = opt->fps;
    if (opt && opt->has_alpha)
        e->alpha_mode = opt->alpha;
    if (opt && opt->width > 0) {
        e->width = opt->width;
        e->height = opt->height;
    }
}

/* Bounds on the work the effect asks for, checked before any is done (and
 * after the overrides, which change it): the frames, and the simulation
 * steps every frame needs run up to it. */
static void check_work(compiler *c, const pfx_node *root) {
    const pfx_effect *e = c->e;
    const pfx_node *at = pfx_node_get(root, "duration");
    if (!at)
        at = pfx_node_get(root, "fps");
    if (e->duration * e->fps > MAX_FRAMES)
        pfx_read_error(&c->r, at ? at : root, PFX_RULE_TOO_MUCH_WORK,
                       "duration x fps gives %.0f frames; the most is %.0f", e->duration * e->fps,
                       MAX_FRAMES);
    double steps = (e->prewarm + e->duration) * e->sim_rate;
    if (steps > MAX_STEPS) {
        const pfx_node *sim = pfx_node_get(root, "sim");
        const pfx_node *where = pfx_node_get(sim, "prewarm");
        if (!where)
            where = at ? at : pfx_node_get(sim, "rate");
        pfx_read_error(&c->r, where ? where : root, PFX_RULE_TOO_MUCH_WORK,
                       "'prewarm' + 'duration' at %g steps/s is %.0f simulation steps; the most is "
                       "%.0f",
                       e->sim_rate, steps, MAX_STEPS);
    }
}

/* The passes over all the emitters, once each compiled without error and
 * the spawn graph between them is resolved: what needs the whole effect
 * (who is fed by whom, the loop's periods, the horizon, the pools). */
static void finish_emitters(compiler *c, const pfx_node *root, const pfx_node *emitters) {
    pfx_effect *e = c->e;
    const pfx_node *loop = pfx_node_get(root, "loop");
    /* An emitter fed by sub-emitters emits nothing on its own unless
     * it says so. */
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_node *n = emitters->pairs[i].value;
        if (e->emitters[i].spawned_peak > 0 && !pfx_node_get(n, "rate") &&
            !pfx_node_get(n, "interval") && !pfx_node_get(n, "bursts"))
            e->emitters[i].rate = 0;
    }
    if (e->loop)
        pfx_compile_loop(c, root, loop, emitters);
    double end = (e->loop ? e->loop_start : e->prewarm) + e->duration;
    for (size_t i = 0; i < e->emitter_count; i++)
        e->emitters[i].horizon = end - e->emitters[i].start + 1;
    /* Frame 0 of a loop comes after its warm-up: bound those steps too. */
    if (e->loop && end * e->sim_rate > MAX_STEPS)
        pfx_read_error(&c->r, loop, PFX_RULE_TOO_MUCH_WORK,
                       "the loop shows frames from t = %g s (when every particle alive "
                       "repeats), %.0f simulation steps; the most is %.0f: shorten the "
                       "lifetimes or lower sim.rate",
                       e->loop_start, end * e->sim_rate, MAX_STEPS);
    pfx_size_pools(c, emitters);
}

/* The emitters in file order with their spawn events, then, when nothing
 * so far had an error (errors_before is the count pfx_compile started
 * with), the passes over them all. Returns false when out of memory. */
static bool compile_emitters(compiler *c, const pfx_node *root, int errors_before) {
    pfx_effect *e = c->e;
    pfx_diags *d = c->r.d;
    const pfx_node *emitters = pfx_node_get(root, "emitters");
    if (!emitters) {
        pfx_diag_add(d, PFX_SEV_WARNING, root->line, root->col, 1, PFX_RULE_EMPTY_EFFECT,
                     "the effect has no 'emitters': every frame will be empty");
        /* Still a loop of its frames (a period of nothing): the frame
         * count mod the period needs the period. */
        if (e->loop)
            pfx_compile_loop(c, root, pfx_node_get(root, "loop"), NULL);
    } else if (pfx_read_map(&c->r, emitters, "emitters") && emitters->count > PFX_MAX_EMITTERS) {
        /* Before compiling any: the cap bounds the work, not only the
         * result. */
        pfx_read_error(&c->r, emitters, PFX_RULE_TOO_MANY,
                       "an effect has at most %d emitters, got %zu", PFX_MAX_EMITTERS,
                       emitters->count);
    } else if (emitters->kind == PFX_NODE_MAP) {
        e->emitters = pfx_arena_alloc(c->r.arena, (emitters->count + 1) * sizeof *e->emitters);
        if (!e->emitters)
            return false;
        for (size_t i = 0; i < emitters->count; i++) {
            pfx_compile_emitter(c, emitters->pairs[i].key, emitters->pairs[i].value,
                                &e->emitters[e->emitter_count++]);
            if (emitters->pairs[i].value->kind == PFX_NODE_MAP)
                pfx_compile_spawns(&c->r, emitters->pairs[i].value, emitters, &e->emitters[i]);
        }
        if (d->errors == errors_before && pfx_resolve_spawns(&c->r, e, emitters) &&
            pfx_check_ribbons(&c->r, e, emitters))
            finish_emitters(c, root, emitters);
    }
    return true;
}

pfx_effect *pfx_compile(const pfx_node *root, const char *path, const pfx_compile_options *opt,
                        pfx_arena *arena, pfx_diags *d) {
    compiler c = {.r = {d, arena}, .opt = opt};
    int errors_before = d->errors;
    if (!root) {
        pfx_diag_add(d, PFX_SEV_ERROR, 1, 1, 1, PFX_RULE_EMPTY_FILE,
                     "the file is empty; an effect starts with 'pfx: 1' and lists its 'emitters'");
        return NULL;
    }
    if (root->kind != PFX_NODE_MAP) {
        pfx_read_error(&c.r, root, PFX_RULE_WRONG_TYPE,
                       "an effect file must be a mapping of keys, got %s",
                       pfx_node_kind_name(root));
        return NULL;
    }
    pfx_effect *e = pfx_arena_alloc(arena, sizeof *e);
    if (!e)
        return NULL;
    c.e = e;
    effect_defaults(e, path, opt);

    /* Before anything can warn: the acknowledged rules. */
    const pfx_node *v = pfx_node_get(root, "allow");
    if (v)
        pfx_compile_allow(&c, v);
    pfx_keys_check(&c.r, root, &pfx_schema_top, "the effect");
    if (!pfx_node_get(root, "pfx"))
        pfx_diag_add(d, PFX_SEV_ERROR, root->line, root->col, 1, PFX_RULE_FORMAT_VERSION,
                     "missing 'pfx: 1' (the format version) at the top of the effect");
    pfx_keys_read(&c.r, root, &pfx_schema_top, e);
    if ((v = pfx_node_get(root, "camera")))
        compile_camera(&c, v);
    if (opt && opt->has_seed)
        e->seed = opt->seed;
    if ((v = pfx_node_get(root, "forces")))
        compile_forces(&c, v);
    if ((v = pfx_node_get(root, "deflectors")))
        compile_deflectors(&c, v);
    apply_overrides(e, opt);
    check_work(&c, root);
    if (!compile_emitters(&c, root, errors_before))
        return NULL;
    pfx_check_shadows(&c.r, root, e);
    return d->errors == errors_before ? e : NULL;
}
