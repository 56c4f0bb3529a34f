/* pfx_compile: the effect format's keys, defaults and rules. It walks the
 * node tree once, reports every problem it finds (not only the first), and
 * fills a pfx_effect in the caller's arena. Pool sizes and the per-emitter
 * force sums are derived here, so the simulation only reads. */
#include "compile/compile.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "compile/compile_appearance.h"
#include "compile/compile_deflectors.h"
#include "compile/compile_emission.h"
#include "compile/compile_forces.h"
#include "compile/compile_kill.h"
#include "compile/compile_shape.h"
#include "compile/compile_spawn.h"
#include "compile/read.h"

/* Bounds that keep any file's cost finite; each is documented in
 * man/pfx-effect.5. */
#define MAX_IMAGE_SIDE 16384
#define MAX_SIM_RATE 100000.0
#define MAX_SECONDS 86400.0
#define MAX_FPS 1000.0
#define MAX_FRAMES 1000000.0
#define MAX_STEPS 1e8

static const char *const top_keys[] = {"pfx",        "duration", "fps",   "seed",
                                       "sim",        "camera",   "image", "forces",
                                       "deflectors", "emitters", "loop",  NULL};
static const char *const sim_keys[] = {"rate",      "prewarm",  "integrator",
                                       "tolerance", "substeps", NULL};
static const char *const camera_keys[] = {"position", "target", "up", "fov", "ortho", NULL};
static const char *const image_keys[] = {"size", "background", NULL};
/* clang-format off */
static const char *const emitter_keys[] = {
    "shape", "position", "rotation", "rate", "interval", "bursts", "start", "duration", "loop",
    "direction", "spread", "distance", "inherit_velocity", "speed", "lifetime", "size", "color",
    "alpha", "angle", "spin", "sprite", "forces", "deflectors", "gravity_scale", "charge", "mass", "on_birth", "on_death",
    "on_hit", "trail", "lod", "integrator", "kill", "bounds", "blend", NULL};
/* clang-format on */
static const char *const blend_modes[] = {"add", "alpha", NULL};

typedef struct compiler {
    pfx_reader r;
    pfx_effect *e;
    const pfx_compile_options *opt;
} compiler;

/* Reads an optional number into *out (keeping the default when absent) and
 * checks it against [lo, hi] (strict bounds where asked). */
static bool opt_number(compiler *c, const pfx_node *map, const char *key, double *out, double lo,
                       bool lo_strict, double hi) {
    const pfx_node *n = pfx_node_get(map, key);
    if (!n)
        return true;
    double v;
    if (!pfx_read_number(&c->r, n, key, &v))
        return false;
    if (!pfx_check_above(&c->r, n, key, v, lo, lo_strict) ||
        !pfx_check_below(&c->r, n, key, v, hi, false))
        return false;
    *out = v;
    return true;
}

static bool opt_vec3(compiler *c, const pfx_node *map, const char *key, double out[3]) {
    const pfx_node *n = pfx_node_get(map, key);
    return !n || pfx_read_numbers(&c->r, n, key, out, 3);
}

static int read_enum(compiler *c, const pfx_node *n, const char *key, const char *what,
                     const char *const *names) {
    return pfx_read_enum(&c->r, n, key, what, names);
}

static void normalize3(double v[3]) {
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int i = 0; i < 3; i++)
        v[i] /= len;
}

static const char *const integrator_names[] = {"auto",   "euler", "symplectic", "midpoint", "rk4",
                                               "verlet", "exact", "boris",      NULL};

static void read_integrator(compiler *c, const pfx_node *n, pfx_integrator *out) {
    int i = read_enum(c, n, "integrator", "integrator", integrator_names);
    if (i >= 0)
        pfx_integrator_parse(integrator_names[i], out);
}

static void compile_sim(compiler *c, const pfx_node *sim) {
    if (!pfx_read_map(&c->r, sim, "sim"))
        return;
    pfx_read_check_keys(&c->r, sim, sim_keys, "'sim'");
    opt_number(c, sim, "rate", &c->e->sim_rate, 1, false, MAX_SIM_RATE);
    opt_number(c, sim, "prewarm", &c->e->prewarm, 0, false, MAX_SECONDS);
    opt_number(c, sim, "tolerance", &c->e->tolerance, 1e-12, false, 1e6);
    double substeps = 0;
    const pfx_node *n = pfx_node_get(sim, "substeps");
    if (opt_number(c, sim, "substeps", &substeps, 1, false, PFX_MOTION_MAX_SUBSTEPS) && n &&
        substeps != floor(substeps))
        pfx_read_error(&c->r, n, "'substeps' must be a whole number, got %g", substeps);
    c->e->substeps = (int)substeps;
    if ((n = pfx_node_get(sim, "integrator")))
        read_integrator(c, n, &c->e->integrator);
}

static void compile_camera(compiler *c, const pfx_node *cam) {
    pfx_camera *k = &c->e->camera;
    if (!pfx_read_map(&c->r, cam, "camera"))
        return;
    pfx_read_check_keys(&c->r, cam, camera_keys, "'camera'");
    bool ok = opt_vec3(c, cam, "position", k->position) & opt_vec3(c, cam, "target", k->target) &
              opt_vec3(c, cam, "up", k->up);
    const pfx_node *fov = pfx_node_get(cam, "fov"), *ortho = pfx_node_get(cam, "ortho");
    if (fov && ortho) {
        pfx_read_error(&c->r, ortho, "'camera' takes either 'fov' or 'ortho', not both");
        return;
    }
    if (fov && pfx_read_number(&c->r, fov, "fov", &k->fov_deg)) {
        if (!(k->fov_deg > 0 && k->fov_deg < 180))
            pfx_read_error(&c->r, fov,
                           "'fov' must be between 0 and 180 degrees (exclusive), got %g",
                           k->fov_deg);
    }
    if (ortho && pfx_read_number(&c->r, ortho, "ortho", &k->ortho_height)) {
        k->ortho = true;
        pfx_check_above(&c->r, ortho, "ortho", k->ortho_height, 0, true);
    }
    if (!ok)
        return;
    double dir[3], cross[3];
    for (int i = 0; i < 3; i++)
        dir[i] = k->target[i] - k->position[i];
    cross[0] = dir[1] * k->up[2] - dir[2] * k->up[1];
    cross[1] = dir[2] * k->up[0] - dir[0] * k->up[2];
    cross[2] = dir[0] * k->up[1] - dir[1] * k->up[0];
    double dlen = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    double clen = sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
    const pfx_node *target = pfx_node_get(cam, "target"), *up = pfx_node_get(cam, "up");
    if (dlen == 0)
        pfx_read_error(&c->r, target ? target : cam,
                       "camera 'position' and 'target' are the same point");
    else if (clen == 0)
        pfx_read_error(&c->r, up ? up : cam, "camera 'up' is parallel to the view direction");
}

static void compile_image(compiler *c, const pfx_node *img) {
    if (!pfx_read_map(&c->r, img, "image"))
        return;
    pfx_read_check_keys(&c->r, img, image_keys, "'image'");
    const pfx_node *size = pfx_node_get(img, "size"), *bg = pfx_node_get(img, "background");
    double wh[2];
    if (size && pfx_read_numbers(&c->r, size, "size", wh, 2)) {
        for (int i = 0; i < 2; i++) {
            const pfx_node *n = size->items[i];
            if (wh[i] != floor(wh[i]) || wh[i] < 1 || wh[i] > MAX_IMAGE_SIDE)
                pfx_read_error(&c->r, n,
                               "image 'size' must be whole numbers of pixels from 1 to %d, got %g",
                               MAX_IMAGE_SIDE, wh[i]);
        }
        c->e->width = (int)fmin(fmax(wh[0], 1), MAX_IMAGE_SIDE);
        c->e->height = (int)fmin(fmax(wh[1], 1), MAX_IMAGE_SIDE);
    }
    if (bg)
        pfx_read_color(&c->r, bg, "background", c->e->background);
}

static void compile_forces(compiler *c, const pfx_node *forces) {
    if (!pfx_read_map(&c->r, forces, "forces"))
        return;
    if (forces->count > PFX_MAX_FORCES) {
        pfx_read_error(&c->r, forces, "an effect has at most %d forces, got %zu", PFX_MAX_FORCES,
                       forces->count);
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
        pfx_read_error(&c->r, defl, "an effect has at most %d deflectors, got %zu",
                       PFX_MAX_DEFLECTORS, defl->count);
        return;
    }
    c->e->deflectors = pfx_arena_alloc(c->r.arena, (defl->count + 1) * sizeof *c->e->deflectors);
    if (!c->e->deflectors)
        return;
    for (size_t i = 0; i < defl->count; i++)
        pfx_compile_deflector(&c->r, defl->pairs[i].key, defl->pairs[i].value, c->e->seed,
                              &c->e->deflectors[c->e->deflector_count++]);
}

/* An emitter's `deflectors: [names]` (default: all of them), copied into
 * the emitter so the collision pass reads one dense array. */
static void emitter_deflectors(compiler *c, const pfx_node *n, pfx_emitter *em) {
    const pfx_effect *e = c->e;
    const pfx_node *v = pfx_node_get(n, "deflectors");
    bool use[PFX_MAX_DEFLECTORS] = {0};
    for (size_t i = 0; i < e->deflector_count; i++)
        use[i] = !v;
    if (v && v->kind != PFX_NODE_SEQ) {
        pfx_read_error(&c->r, v, "'deflectors' must be a list of deflector names, got %s",
                       pfx_node_kind_name(v));
    } else if (v) {
        const char *names[PFX_MAX_DEFLECTORS + 1];
        for (size_t i = 0; i < e->deflector_count; i++)
            names[i] = e->deflectors[i].name;
        names[e->deflector_count] = NULL;
        for (size_t i = 0; i < v->count; i++) {
            const char *name;
            if (!pfx_read_string(&c->r, v->items[i], "deflectors", &name))
                continue;
            size_t k = 0;
            while (k < e->deflector_count && strcmp(names[k], name))
                k++;
            if (k < e->deflector_count) {
                use[k] = true;
                continue;
            }
            const char *sug = pfx_suggest(name, names);
            if (sug)
                pfx_read_error(&c->r, v->items[i],
                               "unknown deflector '%s' in emitter '%s'; did you mean '%s'?", name,
                               em->name, sug);
            else
                pfx_read_error(&c->r, v->items[i],
                               "unknown deflector '%s' in emitter '%s'; define it under "
                               "'deflectors'",
                               name, em->name);
        }
    }
    size_t count = 0;
    for (size_t i = 0; i < e->deflector_count; i++)
        count += use[i];
    if (!count)
        return;
    em->deflectors = pfx_arena_alloc(c->r.arena, count * sizeof *em->deflectors);
    if (!em->deflectors)
        return;
    for (size_t i = 0; i < e->deflector_count; i++)
        if (use[i]) {
            em->deflectors[em->deflector_count++] = e->deflectors[i];
            em->sticks |= e->deflectors[i].response == PFX_DEFLECT_STICK;
        }
}

static int find_force(const pfx_effect *e, const char *name) {
    for (size_t i = 0; i < e->force_count; i++)
        if (!strcmp(e->forces[i].name, name))
            return (int)i;
    return -1;
}

/* Reads a value and checks every sample it can take against [lo, hi]. */
static bool range_value(compiler *c, const pfx_node *n, const char *what, pfx_value *v, double lo,
                        bool lo_strict, double hi) {
    return pfx_read_value_in(&c->r, n, what, v, lo, lo_strict, hi);
}

/* `kill:` rules and `bounds:` (src/sim/kill.c applies them each step).
 * alpha_below reads the alpha over life: the gradient's (or, for colours
 * fixed at birth, the colour's largest) times the alpha curve. */
static void compile_kill(compiler *c, const pfx_node *n, pfx_emitter *em) {
    const pfx_node *kill_node = pfx_node_get(n, "kill"), *bounds_node = pfx_node_get(n, "bounds");
    pfx_kill_rules rules;
    if (!(kill_node || bounds_node) || !pfx_compile_kill(&c->r, kill_node, bounds_node, &rules) ||
        pfx_kill_rules_empty(&rules) || !(em->kill = pfx_arena_alloc(c->r.arena, sizeof rules)))
        return;
    *em->kill = rules;
    for (int k = 0; k < PFX_GRADIENT_LUT; k++) {
        float a = em->color.lut[k][3];
        if (em->color_mode == PFX_COLOR_RANDOM)
            a = em->color_a[3] > em->color_b[3] ? em->color_a[3] : em->color_b[3];
        else if (em->color_mode == PFX_COLOR_PICK)
            for (int j = 0; j < PFX_GRADIENT_LUT; j++)
                a = em->color.lut[j][3] > a ? em->color.lut[j][3] : a;
        em->alpha_at_age[k] = a * (em->alpha_curve ? em->alpha_lut[k] : 1.0f);
    }
    if (pfx_kill_needs_alpha(em->kill))
        for (size_t i = 0; i < em->kill->count; i++)
            if (em->kill->rules[i].kind == PFX_KILL_ALPHA_BELOW &&
                em->alpha_at_age[0] < em->kill->rules[i].threshold)
                pfx_read_warning(&c->r, kill_node,
                                 "emitter '%s' is born with alpha %g, below its 'alpha_below' "
                                 "%g: every particle dies in its first step",
                                 em->name, em->alpha_at_age[0], em->kill->rules[i].threshold);
}

/* The radius of a sphere around the emitter's origin holding its shape. */
static double shape_radius(const pfx_shape *s) {
    switch (s->type) {
    case PFX_SHAPE_BOX:
        return 0.5 *
               sqrt(s->size[0] * s->size[0] + s->size[1] * s->size[1] + s->size[2] * s->size[2]);
    case PFX_SHAPE_RECT:
        return 0.5 * sqrt(s->size[0] * s->size[0] + s->size[1] * s->size[1]);
    case PFX_SHAPE_ELLIPSE:
        return fmax(s->radii[0], s->radii[1]);
    case PFX_SHAPE_LINE:
        return fmax(sqrt(s->line_from[0] * s->line_from[0] + s->line_from[1] * s->line_from[1] +
                         s->line_from[2] * s->line_from[2]),
                    sqrt(s->line_to[0] * s->line_to[0] + s->line_to[1] * s->line_to[1] +
                         s->line_to[2] * s->line_to[2]));
    case PFX_SHAPE_CYLINDER:
    case PFX_SHAPE_CONE:
        return sqrt(s->radius * s->radius + s->height * s->height);
    case PFX_SHAPE_MESH: {
        double r2 = 0;
        for (uint32_t i = 0; s->verts && i < s->cum_count; i++)
            for (int k = 0; k < 3; k++) {
                const double *v = &s->verts[3 * s->tris[3 * i + k]];
                r2 = fmax(r2, v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            }
        return sqrt(r2);
    }
    default:
        return s->radius;
    }
}

/* Reeves' level of detail: births per second = (per_pixel + R var) x the
 * emitter's area on screen, the projected disc of its shape's bounding
 * sphere seen from the camera (at least one pixel). A distant, small
 * effect spends fewer particles and looks the same. */
static void compile_lod(compiler *c, const pfx_node *v, const pfx_node *n, pfx_emitter *em) {
    static const char *const lod_keys[] = {"per_pixel", "var", NULL};
    if (!pfx_read_map(&c->r, v, "lod") || !pfx_read_check_keys(&c->r, v, lod_keys, "'lod'"))
        return;
    if (pfx_node_get(n, "rate") || pfx_node_get(n, "interval")) {
        pfx_read_error(&c->r, v, "'lod' sets the rate from the screen area; drop 'rate'");
        return;
    }
    double per_pixel = 1, var = 0;
    opt_number(c, v, "per_pixel", &per_pixel, 0, false, 1e6);
    opt_number(c, v, "var", &var, 0, false, 1e6);
    const pfx_camera *k = &c->e->camera;
    double view[3], to[3], depth = 0, vlen = 0;
    for (int a = 0; a < 3; a++) {
        view[a] = k->target[a] - k->position[a];
        to[a] = em->position[a] - k->position[a];
        vlen += view[a] * view[a];
    }
    vlen = sqrt(vlen);
    for (int a = 0; a < 3; a++)
        depth += to[a] * view[a] / (vlen > 0 ? vlen : 1);
    double pixels_per_metre =
        k->ortho ? c->e->height / k->ortho_height
                 : (depth > 1e-6 ? 0.5 * c->e->height / (tan(0.5 * k->fov_deg * M_PI / 180) * depth)
                                 : 0);
    double r_px = shape_radius(&em->shape) * pixels_per_metre;
    em->lod_area = fmax(1.0, M_PI * r_px * r_px);
    em->rate_kind = var > 0 ? PFX_RATE_RANDOM : PFX_RATE_CONSTANT;
    em->rate = fmin(per_pixel * em->lod_area, 1e7);
    em->rate_var = fmin(var * em->lod_area, em->rate);
}

/* `direction` (a vector, or normal | radial | inward), `spread` (a cone
 * half-angle, or the thesis's [alpha, beta]), `distance` and
 * `inherit_velocity`. The direction stays in the emitter's frame: the
 * emitter's rotation at each birth turns it. */
static void compile_direction(compiler *c, const pfx_node *n, pfx_emitter *em) {
    static const char *const modes[] = {"normal", "radial", "inward", NULL};
    const pfx_node *v;
    double dir[3] = {0, 1, 0};
    if ((v = pfx_node_get(n, "direction"))) {
        if (v->kind == PFX_NODE_SCALAR) {
            int m = read_enum(c, v, "direction", "direction", modes);
            if (m >= 0)
                em->direction_mode = (pfx_direction_mode)(m + 1);
        } else if (pfx_read_numbers(&c->r, v, "direction", dir, 3) && dir[0] == 0 && dir[1] == 0 &&
                   dir[2] == 0) {
            pfx_read_error(&c->r, v, "'direction' must not be the zero vector");
            dir[1] = 1;
        }
    }
    normalize3(dir);
    memcpy(em->direction, dir, sizeof dir);
    if ((v = pfx_node_get(n, "spread"))) {
        double ab[2];
        if (v->kind == PFX_NODE_SEQ) {
            if (pfx_read_numbers(&c->r, v, "spread", ab, 2) &&
                pfx_check_above(&c->r, v, "spread", fmin(ab[0], ab[1]), 0, false) &&
                pfx_check_below(&c->r, v, "spread", fmax(ab[0], ab[1]), 360, false)) {
                em->spread_two_angle = true;
                em->spread_alpha_deg = ab[0];
                em->spread_beta_deg = ab[1];
            }
        } else {
            opt_number(c, n, "spread", &em->spread_deg, 0, false, 180);
        }
    }
    if ((v = pfx_node_get(n, "distance")))
        range_value(c, v, "distance", &em->distance, -1e6, false, 1e6);
    opt_number(c, n, "inherit_velocity", &em->inherit_velocity, -100, false, 100);
}

/* Decides how the emitter moves. Only unregioned gravity under `auto`: the
 * exact constant-acceleration kernel, no motion model (the fast path).
 * Anything else: a pfx_motion holding just the forces this emitter feels,
 * prepared for the step, and checked against its integrator's stability
 * region; each problem is a warning at `at` with the numbers and a fix. */
static void build_motion(compiler *c, pfx_emitter *em, pfx_integrator integrator,
                         const pfx_node *at) {
    const pfx_effect *e = c->e;
    bool simple = integrator == PFX_INTEGRATOR_AUTO && e->substeps == 0;
    for (size_t i = 0; i < e->force_count; i++) {
        const pfx_motion_force *f = &e->forces[i].spec;
        if (!(em->force_mask & (1u << i)))
            continue;
        if (f->kind == PFX_MOTION_GRAVITY && f->region.kind == PFX_REGION_NONE)
            for (int k = 0; k < 3; k++)
                em->accel[k] += f->accel[k];
        else
            simple = false;
    }
    if (simple)
        return;
    pfx_motion *m = pfx_arena_alloc(c->r.arena, sizeof *m);
    if (!m)
        return;
    m->integrator = integrator;
    m->substeps = e->substeps;
    m->tolerance = e->tolerance;
    double speed_max = fmax(fabs(pfx_value_max(&em->speed)), fabs(pfx_value_min(&em->speed)));
    double q_max = fmax(fabs(pfx_value_max(&em->charge)), fabs(pfx_value_min(&em->charge)));
    for (size_t i = 0; i < e->force_count; i++) {
        if (!(em->force_mask & (1u << i)))
            continue;
        pfx_motion_force *f = &m->forces[m->force_count++];
        *f = e->forces[i].spec;
        /* Stability is judged at the worst case of the per-particle values:
         * the largest charge, the smallest mass, the fastest emission. */
        f->charge = em->charge.dist == PFX_DIST_CONST ? em->charge.a : q_max;
        f->mass = pfx_value_min(&em->mass);
        f->speed_hint = speed_max; /* drag and magnetic judge accuracy by it */
        /* A constant gravity_scale is folded in; a random one is a column. */
        if (f->kind == PFX_MOTION_GRAVITY && em->gravity_scale.dist == PFX_DIST_CONST)
            for (int k = 0; k < 3; k++)
                f->accel[k] *= em->gravity_scale.a;
    }
    pfx_motion_choose(m, 1.0 / e->sim_rate);
    em->motion = m;
    pfx_stability_warning w[8];
    size_t n = pfx_motion_check_stability(m, w, 8);
    for (size_t i = 0; i < n && i < 8; i++)
        pfx_read_warning(&c->r, at, "emitter '%s': %s", em->name, w[i].message);
    const double tol = m->tolerance > 0 ? m->tolerance : 1e-3;
    if (integrator == PFX_INTEGRATOR_AUTO && m->substeps == 0 && m->choice.error_rate > tol)
        pfx_read_warning(&c->r, at,
                         "emitter '%s': auto cannot keep the tolerance of %g m/s: even %d "
                         "substeps leave an expected error of %.2g m/s; raise sim.rate",
                         em->name, tol, m->choice.steps, m->choice.error_rate);
}

static void compile_emitter(compiler *c, const pfx_node *key, const pfx_node *n, pfx_emitter *em) {
    pfx_effect *e = c->e;
    em->name = pfx_arena_strndup(c->r.arena, key->text, key->len);
    /* Defaults: a point emitting 10/s straight up at 1 m/s for 1 s, white,
     * 0.1 m sprites, additive, feeling every force. */
    em->direction[1] = 1;
    em->speed = pfx_value_const(1);
    em->lifetime = pfx_value_const(1);
    em->size_start = em->size_end = pfx_value_const(0.1);
    em->size_same = true;
    em->gravity_scale = pfx_value_const(1);
    for (int i = 0; i < PFX_GRADIENT_LUT; i++)
        for (int k = 0; k < 4; k++)
            em->color.lut[i][k] = 1.0f;
    em->color.constant = true;
    em->force_mask = e->force_count >= 32 ? 0xffffffffu : (1u << e->force_count) - 1;
    em->blend = PFX_BLEND_ADD;
    double rot_deg[3] = {0, 0, 0};
    pfx_rotation_from_degrees(rot_deg, em->rotation);

    char where[160];
    snprintf(where, sizeof where, "emitter '%s'", key->text);
    if (!pfx_read_map(&c->r, n, key->text))
        return;
    pfx_read_check_keys(&c->r, n, emitter_keys, where);
    const pfx_node *v;
    if ((v = pfx_node_get(n, "shape")))
        pfx_compile_shape(&c->r, v, &em->shape, em->name, e->path);
    if ((v = pfx_node_get(n, "position")))
        pfx_read_keys3(&c->r, v, "position", em->position, &em->position_keys);
    if ((v = pfx_node_get(n, "rotation")) &&
        pfx_read_keys3(&c->r, v, "rotation", rot_deg, &em->rotation_keys))
        pfx_rotation_from_degrees(rot_deg, em->rotation);
    pfx_compile_emission(&c->r, n, em);
    if ((v = pfx_node_get(n, "lod")))
        compile_lod(c, v, n, em);
    compile_direction(c, n, em);
    if ((v = pfx_node_get(n, "speed")))
        range_value(c, v, "speed", &em->speed, -1e6, false, 1e6);
    if ((v = pfx_node_get(n, "lifetime")))
        range_value(c, v, "lifetime", &em->lifetime, 0, true, MAX_SECONDS);
    em->max_lifetime = pfx_value_max(&em->lifetime);
    pfx_compile_appearance(&c->r, n, em);
    compile_kill(c, n, em);
    if ((v = pfx_node_get(n, "gravity_scale")))
        range_value(c, v, "gravity_scale", &em->gravity_scale, -1e3, false, 1e3);
    if ((v = pfx_node_get(n, "blend"))) {
        int b = read_enum(c, v, "blend", "blend mode", blend_modes);
        if (b >= 0)
            em->blend = b == 0 ? PFX_BLEND_ADD : PFX_BLEND_ALPHA;
    }
    if ((v = pfx_node_get(n, "forces"))) {
        em->force_mask = 0;
        if (v->kind != PFX_NODE_SEQ) {
            pfx_read_error(&c->r, v, "'forces' must be a list of force names, got %s",
                           pfx_node_kind_name(v));
        } else {
            const char *names[PFX_MAX_FORCES + 1];
            for (size_t i = 0; i < e->force_count; i++)
                names[i] = e->forces[i].name;
            names[e->force_count] = NULL;
            for (size_t i = 0; i < v->count; i++) {
                const char *name;
                if (!pfx_read_string(&c->r, v->items[i], "forces", &name))
                    continue;
                int f = find_force(e, name);
                if (f >= 0) {
                    em->force_mask |= 1u << f;
                    continue;
                }
                const char *sug = pfx_suggest(name, names);
                if (sug)
                    pfx_read_error(&c->r, v->items[i],
                                   "unknown force '%s' in emitter '%s'; did you mean '%s'?", name,
                                   key->text, sug);
                else
                    pfx_read_error(&c->r, v->items[i],
                                   "unknown force '%s' in emitter '%s'; define it under 'forces'",
                                   name, key->text);
            }
        }
    }
    em->charge = pfx_value_const(1);
    em->mass = pfx_value_const(1);
    if ((v = pfx_node_get(n, "charge")))
        range_value(c, v, "charge", &em->charge, -1e6, false, 1e6);
    if ((v = pfx_node_get(n, "mass")))
        range_value(c, v, "mass", &em->mass, 0, true, 1e6);
    emitter_deflectors(c, n, em);
    pfx_integrator integrator = e->integrator;
    const pfx_node *integrator_node = pfx_node_get(n, "integrator");
    if (integrator_node)
        read_integrator(c, integrator_node, &integrator);
    build_motion(c, em, integrator, integrator_node ? integrator_node : key);
    em->size_varies = em->size_start.dist != PFX_DIST_CONST ||
                      (!em->size_same && em->size_end.dist != PFX_DIST_CONST);
}

/* A seamless loop of period P = duration: every emitter's schedule repeats
 * with period P (or a divisor it states) and draws the same values each
 * period; keyframes repeat too. Frames come from one period starting once
 * every particle alive belongs to the periodic regime (after the longest
 * start + lifetime chain), so frame N = duration x fps is frame 0. What
 * cannot repeat is a warning at the place that says it. */
static void compile_loop(compiler *c, const pfx_node *root, const pfx_node *loop,
                         const pfx_node *emitters) {
    pfx_effect *e = c->e;
    const double period = e->duration;
    double frames = period * e->fps;
    if (fabs(frames - round(frames)) > 1e-9 * frames) {
        pfx_read_error(&c->r, loop,
                       "a looping effect needs duration x fps to be whole frames, got %g", frames);
        return;
    }
    e->loop_frames = lround(frames);
    double settle = 0;
    for (size_t i = 0; i < e->emitter_count; i++) {
        pfx_emitter *em = &e->emitters[i];
        const pfx_node *n = emitters->pairs[i].value, *v;
        settle += em->max_lifetime; /* a chain of sub-emitters at worst */
        if (em->start > settle)
            settle = em->start + em->max_lifetime;
        em->key_period = period;
        if (!em->loop) {
            em->loop = true;
            em->duration = period;
        } else if (fabs(period / em->duration - round(period / em->duration)) > 1e-9) {
            pfx_read_warning(&c->r, pfx_node_get(n, "duration"),
                             "emitter '%s' repeats every %g s, which does not divide the loop's "
                             "%g s: the loop will show a seam",
                             em->name, em->duration, period);
        }
        const char *keys[] = {"position", "rotation"};
        const pfx_keys3 *kf[] = {&em->position_keys, &em->rotation_keys};
        for (int k = 0; k < 2; k++)
            if (kf[k]->count > 1 &&
                memcmp(kf[k]->v[0], kf[k]->v[kf[k]->count - 1], sizeof(double[3])))
                pfx_read_warning(&c->r, pfx_node_get(n, keys[k]),
                                 "'%s' keyframes end elsewhere than they start: the loop will "
                                 "jump at the seam",
                                 keys[k]);
        if (em->rate_kind == PFX_RATE_CURVE &&
            em->rate_curve.v[0] != em->rate_curve.v[em->rate_curve.count - 1])
            pfx_read_warning(&c->r, pfx_node_get(n, "rate"),
                             "the rate curve ends at another value than it starts: the loop will "
                             "change rate at the seam");
        for (size_t b = 0; b < em->burst_count; b++)
            if (em->bursts[b].cycles == 1 && (v = pfx_node_get(n, "bursts")))
                pfx_read_warning(&c->r, v->items[b],
                                 "a one-shot burst repeats every %g s when the effect loops",
                                 period);
        if (em->spawn_count)
            pfx_read_warning(&c->r, emitters->pairs[i].key,
                             "emitter '%s' has sub-emitters: their random counts do not repeat "
                             "every period, so the loop is not exact",
                             em->name);
        for (size_t d = 0; d < em->deflector_count; d++) {
            const pfx_deflector *df = &em->deflectors[d];
            if (df->resilience[0] != df->resilience[1] || df->friction[0] != df->friction[1])
                pfx_read_warning(&c->r, emitters->pairs[i].key,
                                 "deflector '%s' draws a random response per hit: the loop is "
                                 "not exact",
                                 df->name);
        }
    }
    for (size_t f = 0; f < e->force_count; f++)
        if (e->forces[f].spec.kind == PFX_MOTION_TURBULENCE && e->forces[f].spec.speed != 0) {
            const pfx_node *fn = pfx_node_get(pfx_node_get(root, "forces"), e->forces[f].name);
            const pfx_node *at = pfx_node_get(fn, "speed");
            pfx_read_warning(&c->r, at ? at : root,
                             "turbulence '%s' drifts with 'speed': the loop will show a seam",
                             e->forces[f].name);
        }
    e->loop_start = fmax(e->prewarm, ceil(settle / period - 1e-9) * period);
}

/* Its own births' peak plus what sub-emitters can feed it within one
 * lifetime. */
static double pool_need(const pfx_emitter *em) { return pfx_emitter_peak(em) + em->spawned_peak; }

/* Sizes each emitter's pool from its worst case (rate x max lifetime, plus
 * bursts and sub-emitters). When the total exceeds the particle budget, the
 * budget is shared by water-filling: every emitter gets its need or an
 * equal share of what is left, whichever is smaller, smallest needs first,
 * so a small emitter (a firework's shell) is never starved by a huge one
 * (its sparks). Cut emitters saturate, with a warning giving the numbers. */
static void size_pools(compiler *c, const pfx_node *emitters) {
    pfx_effect *e = c->e;
    size_t n = e->emitter_count;
    double need[1024], cap[1024];
    size_t order[1024];
    double need_total = 0;
    for (size_t i = 0; i < n && i < 1024; i++) {
        need[i] = pool_need(&e->emitters[i]);
        need_total += need[i];
        order[i] = i;
    }
    /* Insertion sort by need: at most 1024 emitters, once per compile. */
    for (size_t i = 1; i < n; i++)
        for (size_t k = i; k > 0 && need[order[k]] < need[order[k - 1]]; k--) {
            size_t t = order[k];
            order[k] = order[k - 1];
            order[k - 1] = t;
        }
    double budget = (double)e->max_particles, left = budget;
    for (size_t k = 0; k < n; k++) {
        size_t i = order[k];
        double share = floor(left / (double)(n - k));
        cap[i] = need[i] <= share ? need[i] : share;
        left -= cap[i];
    }
    for (size_t i = 0; i < n; i++) {
        pfx_emitter *em = &e->emitters[i];
        if (need_total > budget && cap[i] < need[i]) {
            em->saturates = true;
            const pfx_node *at = pfx_node_get(emitters->pairs[i].value, "rate");
            if (!at)
                at = emitters->pairs[i].key;
            pfx_read_warning(&c->r, at,
                             "emitter '%s' needs up to %.0f live particles (%g births/s x max "
                             "lifetime %g s, plus bursts and sub-emitters) but gets %.0f of the "
                             "%.0f budget; it will saturate (raise --max-particles or lower "
                             "'rate' or 'lifetime')",
                             em->name, need[i], pfx_emitter_max_rate(em) + em->spawned_rate,
                             em->max_lifetime, cap[i], budget);
        }
        em->capacity = (uint32_t)(cap[i] < 1 ? 1 : cap[i]);
    }
}

pfx_effect *pfx_compile(const pfx_node *root, const char *path, const pfx_compile_options *opt,
                        pfx_arena *arena, pfx_diags *d) {
    compiler c = {.r = {d, arena}, .opt = opt};
    int errors_before = d->errors;
    if (!root) {
        pfx_diag_add(d, PFX_SEV_ERROR, 1, 1, 1,
                     "the file is empty; an effect starts with 'pfx: 1' and lists its 'emitters'");
        return NULL;
    }
    if (root->kind != PFX_NODE_MAP) {
        pfx_read_error(&c.r, root, "an effect file must be a mapping of keys, got %s",
                       pfx_node_kind_name(root));
        return NULL;
    }
    pfx_effect *e = pfx_arena_alloc(arena, sizeof *e);
    if (!e)
        return NULL;
    c.e = e;
    e->path = path;
    e->duration = 2;
    e->fps = 30;
    e->sim_rate = 120;
    e->width = e->height = 512;
    e->camera = (pfx_camera){{0, 1, 6}, {0, 1, 0}, {0, 1, 0}, false, 40, 0};
    e->max_particles = opt && opt->max_particles ? opt->max_particles : PFX_DEFAULT_MAX_PARTICLES;

    pfx_read_check_keys(&c.r, root, top_keys, "the effect");
    const pfx_node *v = pfx_node_get(root, "pfx");
    if (!v) {
        pfx_diag_add(d, PFX_SEV_ERROR, root->line, root->col, 1,
                     "missing 'pfx: 1' (the format version) at the top of the effect");
    } else {
        double version;
        if (pfx_read_number(&c.r, v, "pfx", &version) && version != PFX_FORMAT_VERSION)
            pfx_read_error(&c.r, v, "unsupported format version '%s'; this pfx reads version %d",
                           v->text, PFX_FORMAT_VERSION);
    }
    opt_number(&c, root, "duration", &e->duration, 0, true, MAX_SECONDS);
    opt_number(&c, root, "fps", &e->fps, 0, true, MAX_FPS);
    if ((v = pfx_node_get(root, "seed")))
        pfx_read_uint(&c.r, v, "seed", &e->seed);
    if ((v = pfx_node_get(root, "sim")))
        compile_sim(&c, v);
    if ((v = pfx_node_get(root, "camera")))
        compile_camera(&c, v);
    if ((v = pfx_node_get(root, "image")))
        compile_image(&c, v);
    if (opt && opt->has_seed)
        e->seed = opt->seed;
    if ((v = pfx_node_get(root, "forces")))
        compile_forces(&c, v);
    if ((v = pfx_node_get(root, "deflectors")))
        compile_deflectors(&c, v);

    if (opt && opt->fps > 0)
        e->fps = opt->fps;
    if (opt && opt->width > 0) {
        e->width = opt->width;
        e->height = opt->height;
    }
    const pfx_node *at = pfx_node_get(root, "duration");
    if (!at)
        at = pfx_node_get(root, "fps");
    if (e->duration * e->fps > MAX_FRAMES)
        pfx_read_error(&c.r, at ? at : root, "duration x fps gives %.0f frames; the most is %.0f",
                       e->duration * e->fps, MAX_FRAMES);
    /* Every frame needs the simulation run up to it: bound the steps. */
    double steps = (e->prewarm + e->duration) * e->sim_rate;
    if (steps > MAX_STEPS) {
        const pfx_node *sim = pfx_node_get(root, "sim");
        const pfx_node *where = pfx_node_get(sim, "prewarm");
        if (!where)
            where = at ? at : pfx_node_get(sim, "rate");
        pfx_read_error(&c.r, where ? where : root,
                       "'prewarm' + 'duration' at %g steps/s is %.0f simulation steps; the most is "
                       "%.0f",
                       e->sim_rate, steps, MAX_STEPS);
    }

    const pfx_node *loop = pfx_node_get(root, "loop");
    if (loop) {
        if (loop->kind != PFX_NODE_SCALAR ||
            (strcmp(loop->text, "true") && strcmp(loop->text, "false")))
            pfx_read_error(&c.r, loop, "'loop' must be true or false");
        else
            e->loop = !strcmp(loop->text, "true");
    }
    const pfx_node *emitters = pfx_node_get(root, "emitters");
    if (!emitters) {
        pfx_diag_add(d, PFX_SEV_WARNING, root->line, root->col, 1,
                     "the effect has no 'emitters': every frame will be empty");
    } else if (pfx_read_map(&c.r, emitters, "emitters")) {
        e->emitters = pfx_arena_alloc(arena, (emitters->count + 1) * sizeof *e->emitters);
        if (!e->emitters)
            return NULL;
        for (size_t i = 0; i < emitters->count; i++) {
            compile_emitter(&c, emitters->pairs[i].key, emitters->pairs[i].value,
                            &e->emitters[e->emitter_count++]);
            if (emitters->pairs[i].value->kind == PFX_NODE_MAP)
                pfx_compile_spawns(&c.r, emitters->pairs[i].value, emitters, &e->emitters[i]);
        }
        if (d->errors == errors_before && pfx_resolve_spawns(&c.r, e, emitters)) {
            /* An emitter fed by sub-emitters emits nothing on its own unless
             * it says so. */
            for (size_t i = 0; i < e->emitter_count; i++) {
                const pfx_node *n = emitters->pairs[i].value;
                if (e->emitters[i].spawned_peak > 0 && !pfx_node_get(n, "rate") &&
                    !pfx_node_get(n, "interval") && !pfx_node_get(n, "bursts"))
                    e->emitters[i].rate = 0;
            }
            if (e->loop)
                compile_loop(&c, root, loop, emitters);
            double end = (e->loop ? e->loop_start : e->prewarm) + e->duration;
            for (size_t i = 0; i < e->emitter_count; i++)
                e->emitters[i].horizon = end - e->emitters[i].start + 1;
            /* Frame 0 of a loop comes after its warm-up: bound those steps too. */
            if (e->loop && end * e->sim_rate > MAX_STEPS)
                pfx_read_error(&c.r, loop,
                               "the loop shows frames from t = %g s (when every particle alive "
                               "repeats), %.0f simulation steps; the most is %.0f: shorten the "
                               "lifetimes or lower sim.rate",
                               e->loop_start, end * e->sim_rate, MAX_STEPS);
            size_pools(&c, emitters);
        }
    }
    return d->errors == errors_before ? e : NULL;
}

pfx_effect *pfx_load(pfx_loaded *l, const char *path, const pfx_compile_options *opt) {
    memset(l, 0, sizeof *l);
    pfx_diags_init(&l->diags, path, NULL, 0);
    FILE *f = fopen(path, "rb");
    if (!f) {
        pfx_diag_add(&l->diags, PFX_SEV_ERROR, 0, 0, 0, "cannot open '%s': %s", path,
                     strerror(errno));
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
    bool read_error = ferror(f);
    fclose(f);
    if (!buf || read_error) {
        pfx_diag_add(&l->diags, PFX_SEV_ERROR, 0, 0, 0, "cannot read '%s'", path);
        free(buf);
        return NULL;
    }
    buf[len] = 0;
    l->source = buf;
    l->source_len = len;
    l->diags.source = buf;
    l->diags.source_len = len;
    if (len > PFX_MAX_FILE_BYTES) {
        pfx_diag_add(&l->diags, PFX_SEV_ERROR, 0, 0, 0,
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
        pfx_diag_add(&l->diags, PFX_SEV_ERROR, line, col, 1,
                     "the file contains NUL bytes; an effect file is UTF-8 text");
        return NULL;
    }
    if (!pfx_parse(buf, len, &l->doc, &l->diags))
        return NULL;
    l->effect = pfx_compile(l->doc.root, path, opt, &l->arena, &l->diags);
    return l->effect;
}

void pfx_loaded_free(pfx_loaded *l) {
    pfx_doc_free(&l->doc);
    pfx_arena_free(&l->arena);
    pfx_diags_free(&l->diags);
    free(l->source);
    memset(l, 0, sizeof *l);
}
