/* How particles are drawn, beyond size and colour: the built-in sprite or a
 * texture, a flipbook over it, the orientation (camera, stretched along the
 * velocity, an axis, a world plane), lighting and intensity; and the
 * effect's light and image settings (exposure, tone curve, alpha, dither,
 * motion blur). Textures are read here, so a missing or broken file is an
 * error at its key, before anything runs. */
#include "compile/compile_look.h"

#include "compile/compile_appearance.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "output/png_read.h"

#define B(field) offsetof(pfx_flipbook, field)
#define L(field) offsetof(pfx_look, field)
#define E(field) offsetof(pfx_effect, field)

/* ---- The flipbook ---- */

static void read_grid(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map;
    pfx_flipbook *b = dest;
    double g[2];
    if (!pfx_read_numbers(r, v, "grid", g, 2))
        return;
    for (int i = 0; i < 2; i++)
        if (g[i] != floor(g[i]) || g[i] < 1 || g[i] > 256) {
            pfx_read_error(r, v->items[i], PFX_RULE_OUT_OF_RANGE,
                           "'grid' takes whole numbers of cells from 1 to 256, got %g", g[i]);
            return;
        }
    b->cols = (int)g[0];
    b->rows = (int)g[1];
}

static void read_over(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    static const char *const overs[] = {"life", NULL};
    pfx_flipbook *b = dest;
    if (pfx_node_get(map, "fps")) {
        pfx_read_error(r, v, PFX_RULE_CONFLICTING_KEYS,
                       "a flipbook plays at 'fps' or 'over: life', not both");
        return;
    }
    if (pfx_read_enum(r, v, "over", "flipbook timing", overs) == 0)
        b->fps = 0;
}

static void read_start(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map;
    static const char *const starts[] = {"0", "random", NULL};
    pfx_flipbook *b = dest;
    int k = pfx_read_enum(r, v, "start", "flipbook start", starts);
    if (k >= 0)
        b->random_start = k == 1;
}

static const pfx_key flipbook_keys[] = {
    {"grid", PFX_KEY_CODE, PFX_KEY_REQUIRED, .offset = -1, .hook = read_grid,
     .schema = "{\"type\": \"array\", \"items\": {\"type\": \"integer\", \"minimum\": 1, "
               "\"maximum\": 256}, \"minItems\": 2, \"maxItems\": 2}",
     .doc = "[columns, rows] of equal cells; they must divide the texture's width and height."},
    {"frames", PFX_KEY_WHOLE, PFX_KEY_NO_DEFAULT, .lo = 1, .hi = 65536, .offset = B(frames),
     .doc = "Cells used, read row by row from the top left; default columns x rows."},
    {"fps", PFX_KEY_NUMBER, PFX_KEY_LO_STRICT, .lo = 0, .hi = 1000, .def = {0}, .offset = B(fps),
     .doc = "Cells per second of the particle's age, looping; without it the sheet plays once "
            "over the particle's life (over: life)."},
    {"over", PFX_KEY_CODE, .offset = -1, .hook = read_over,
     .schema = "{\"const\": \"life\", \"default\": \"life\"}",
     .doc = "life: the sheet plays once from birth to death (the default when fps is absent)."},
    {"start", PFX_KEY_CODE, .offset = -1, .hook = read_start,
     .schema = "{\"enum\": [0, \"0\", \"random\"]}",
     .doc = "0: every particle starts at the first cell; random: each at its own cell. Default: "
            "random with fps, 0 over life."},
    {"blend", PFX_KEY_BOOL, .def = {0}, .offset = B(blend),
     .doc = "Cross-fade between consecutive cells instead of cutting."},
};
PFX_KEY_TABLE(pfx_flipbook_table, "flipbook", NULL,
              "A texture sheet played over the particle's age (Unity's Texture Sheet Animation, "
              "Unreal's SubUV).",
              flipbook_keys);

static const pfx_key stretch_keys[] = {
    {"length", PFX_KEY_NUMBER, .lo = 0, .hi = 1000, .def = {1}, .offset = L(stretch_length),
     .doc = "Length as a multiple of the size, 0 to 1000."},
    {"speed", PFX_KEY_NUMBER, .lo = 0, .hi = 1000, .def = {0}, .offset = L(stretch_speed),
     .doc = "Seconds of travel added to the length: length = size x length + |v| x speed."},
};
PFX_KEY_TABLE(pfx_stretch_table, "stretch", NULL,
              "How long a velocity-aligned sprite is: size x length + |v| x speed metres.",
              stretch_keys);

/* taper: [HEAD, TAIL], each a fraction of the strip's length in [0, 1]. */
static void read_taper(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map;
    double t[2];
    if (!pfx_read_numbers(r, v, "taper", t, 2))
        return;
    for (int i = 0; i < 2; i++)
        if (!(t[i] >= 0 && t[i] <= 1)) {
            pfx_read_error(r, v->items[i], PFX_RULE_OUT_OF_RANGE,
                           "'taper' takes fractions of the ribbon's length from 0 to 1, got %g",
                           t[i]);
            return;
        }
    memcpy(((pfx_look *)dest)->ribbon_taper, t, sizeof t);
}

static const pfx_key ribbon_keys[] = {
    {"taper", PFX_KEY_CODE, .offset = -1, .hook = read_taper,
     .schema = "{\"type\": \"array\", \"items\": {\"type\": \"number\", \"minimum\": 0, "
               "\"maximum\": 1}, \"minItems\": 2, \"maxItems\": 2, \"default\": [0, 0]}",
     .doc = "[head, tail]: the fractions of the ribbon's length over which its width and alpha "
            "rise linearly from 0 at the head (the newest end) and fall to 0 at the tail, on top "
            "of each point's size and alpha over life."},
};
PFX_KEY_TABLE(pfx_ribbon_table, "ribbon", NULL,
              "How a draw: ribbon strip is shaped along its length.", ribbon_keys);

/* ---- The effect's light and image ---- */

static void read_light_direction(pfx_reader *r, const pfx_node *map, const pfx_node *v,
                                 void *dest) {
    (void)map;
    pfx_effect *e = dest;
    double d[3];
    if (!pfx_read_numbers(r, v, "direction", d, 3))
        return;
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0)) {
        pfx_read_error(r, v, PFX_RULE_ZERO_VECTOR, "'direction' must not be the zero vector");
        return;
    }
    for (int i = 0; i < 3; i++)
        e->light_dir[i] = d[i] / len;
}

static void read_hdr_colour(pfx_reader *r, const pfx_node *v, const char *key, float out[3]) {
    float c[4];
    if (pfx_read_color(r, v, key, PFX_HDR_MAX, c))
        memcpy(out, c, 3 * sizeof(float));
}

static void read_light_color(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map;
    read_hdr_colour(r, v, "color", ((pfx_effect *)dest)->light_color);
}

static void read_light_ambient(pfx_reader *r, const pfx_node *map, const pfx_node *v, void *dest) {
    (void)map;
    read_hdr_colour(r, v, "ambient", ((pfx_effect *)dest)->light_ambient);
}

static const pfx_key light_keys[] = {
    {"direction", PFX_KEY_VEC3, PFX_KEY_NONZERO, .def = {0, -1, 0}, .offset = -1,
     .hook = read_light_direction,
     .doc = "The direction the light travels (any length, not [0, 0, 0]); default straight down."},
    {"color", PFX_KEY_CODE, .offset = -1, .hook = read_light_color,
     .schema = "{\"$ref\": \"#/$defs/hdr_colour\", \"default\": [1, 1, 1]}",
     .doc = "The light's colour (components may exceed 1)."},
    {"ambient", PFX_KEY_CODE, .offset = -1, .hook = read_light_ambient,
     .schema = "{\"$ref\": \"#/$defs/hdr_colour\", \"default\": [0.25, 0.25, 0.25]}",
     .doc = "Light from every side, added to the directional light."},
    {"shadows", PFX_KEY_BOOL, .def = {0}, .offset = E(light_shadows),
     .doc = "Lit sprites are darkened by the alpha-blended particles between them and the light "
            "(an opacity shadow map), so smoke shades itself."},
    {"shadow_density", PFX_KEY_NUMBER, .lo = 0, .hi = 100, .def = {1}, .offset = E(shadow_density),
     .doc = "Multiplies the optical depth the casters' alpha gives, 0 to 100: below 1 lighter "
            "shadows for thin smoke, above 1 darker for dense."},
};
PFX_KEY_TABLE(pfx_light_table, "light", NULL,
              "One directional light for emitters with lit: true (the default light when absent).",
              light_keys);

static const pfx_key motion_blur_keys[] = {
    {"shutter", PFX_KEY_NUMBER, PFX_KEY_LO_STRICT, .lo = 0, .hi = 1, .def = {0.5},
     .offset = E(shutter),
     .doc = "The open fraction of the frame interval, above 0, at most 1: the shutter opens at "
            "the frame's time and stays open shutter / fps seconds."},
    {"samples", PFX_KEY_WHOLE, .lo = 1, .hi = 64, .def = {8}, .offset = E(blur_samples),
     .doc = "Sub-frame times drawn and averaged, 1 to 64, evenly spaced in the open interval."},
};
PFX_KEY_TABLE(pfx_motion_blur_table, "motion_blur", NULL,
              "Motion blur: every frame averages `samples` images at fixed sub-frame times.",
              motion_blur_keys);

void pfx_look_defaults(pfx_effect *e) {
    e->dither = true;
    e->blur_samples = 1;
    e->light_dir[1] = -1;
    e->shadow_density = 1;
    for (int i = 0; i < 3; i++) {
        e->light_color[i] = 1;
        e->light_ambient[i] = 0.25f;
    }
}

void pfx_compile_light(pfx_reader *r, const pfx_node *v, pfx_effect *e) {
    if (!pfx_read_map(r, v, "light"))
        return;
    pfx_keys_check(r, v, &pfx_light_table, "'light'");
    pfx_keys_read(r, v, &pfx_light_table, e);
    e->has_light = true;
}

void pfx_check_shadows(pfx_reader *r, const pfx_node *root, const pfx_effect *e) {
    if (!e->light_shadows)
        return;
    for (size_t i = 0; i < e->emitter_count; i++)
        if (e->emitters[i].look.lit && e->emitters[i].look.draw == PFX_DRAW_SPRITE)
            return;
    pfx_read_warning(r, pfx_node_get(pfx_node_get(root, "light"), "shadows"),
                     PFX_RULE_INEFFECTIVE_SETTING,
                     "light 'shadows' has nothing to darken: no emitter is lit (add lit: true)");
}

/* motion_blur given at all turns it on at its defaults. */
void pfx_compile_motion_blur(pfx_reader *r, const pfx_node *v, pfx_effect *e) {
    if (!pfx_read_map(r, v, "motion_blur"))
        return;
    pfx_keys_check(r, v, &pfx_motion_blur_table, "'motion_blur'");
    pfx_keys_defaults(&pfx_motion_blur_table, e);
    pfx_keys_read(r, v, &pfx_motion_blur_table, e);
}

/* ---- An emitter's look ---- */

/* A texture key: the file read now (or once before, for another name of
 * it), premultiplied unless it is a normal map. */
static const pfx_image *read_texture(pfx_reader *r, const pfx_node *v, const char *key,
                                     const char *effect_path, bool colour) {
    const char *name;
    char path[4096];
    if (!pfx_read_path(r, v, key, effect_path, &name, path, sizeof path))
        return NULL;
    pfx_image *img = pfx_arena_alloc(r->arena, sizeof *img);
    if (!img)
        return NULL;
    /* A file named before (by this key or another emitter's) shares its
     * pixels: each name keeps its own path for the manifest. */
    const pfx_image *seen = pfx_file_cache_find(r, path, PFX_FILE_TEXTURE, colour);
    if (seen) {
        *img = *seen;
        img->path = name; /* as this key wrote it, not as the first did */
    } else {
        pfx_diag_at at = pfx_read_at(r, v);
        if (!pfx_png_read_texture(path, name, colour, r->arena, img, &at))
            return NULL;
        pfx_file_cache_add(r, path, PFX_FILE_TEXTURE, colour, img);
    }
    img->file = pfx_arena_strndup(r->arena, path, strlen(path));
    return img->file ? img : NULL;
}

/* The grid must cut the texture into whole equal cells, and hold the
 * frames asked for. */
static void check_flipbook(pfx_reader *r, const pfx_node *v, pfx_look *look) {
    pfx_flipbook *b = &look->flipbook;
    if (!b->cols)
        return; /* reported at 'grid' */
    if (!b->frames)
        b->frames = b->cols * b->rows;
    /* A looping sheet played in step by every particle is the classic
     * tell: each starts at its own cell unless `start` says otherwise. A
     * sheet over life (an explosion's stages) starts at its first cell. */
    if (b->fps > 0 && !pfx_node_get(v, "start"))
        b->random_start = true;
    const pfx_image *t = look->texture;
    if (!t) {
        pfx_read_error(r, v, PFX_RULE_MISSING_KEY,
                       "a flipbook needs a 'texture' to cut into cells");
        b->frames = 0;
        return;
    }
    if (t->width % b->cols || t->height % b->rows) {
        pfx_read_error(r, pfx_node_get(v, "grid"), PFX_RULE_INCONSISTENT_VALUES,
                       "a %dx%d grid does not divide the %dx%d texture '%s' into equal cells",
                       b->cols, b->rows, t->width, t->height, t->path);
        b->frames = 0;
    } else if (b->frames > b->cols * b->rows) {
        pfx_read_error(r, pfx_node_get(v, "frames"), PFX_RULE_INCONSISTENT_VALUES,
                       "'frames' is %d but a %dx%d grid has %d cells", b->frames, b->cols, b->rows,
                       b->cols * b->rows);
        b->frames = 0;
    }
}

/* The axis of `align: axis` or the plane normal of `align: world` (unit;
 * default +y). */
static void read_align_vector(pfx_reader *r, const pfx_node *n, pfx_look *look) {
    const bool axis = look->align == PFX_ALIGN_AXIS;
    const char *key = axis ? "axis" : "normal", *other = axis ? "normal" : "axis";
    const pfx_node *wrong = pfx_node_get(n, other), *v = pfx_node_get(n, key);
    if (wrong)
        pfx_read_error(r, wrong, PFX_RULE_INAPPLICABLE_KEY, "'%s' belongs to align: %s", other,
                       axis ? "world" : "axis");
    look->axis[0] = look->axis[2] = 0;
    look->axis[1] = 1;
    double d[3];
    if (!v || !pfx_read_numbers(r, v, key, d, 3))
        return;
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0)) {
        pfx_read_error(r, v, PFX_RULE_ZERO_VECTOR, "'%s' must not be the zero vector", key);
        return;
    }
    for (int i = 0; i < 3; i++)
        look->axis[i] = d[i] / len;
}

/* intensity: a number, or a curve [{at, value}] over normalised age. */
static void read_intensity(pfx_reader *r, const pfx_node *v, pfx_look *look) {
    if (!(v->kind == PFX_NODE_SEQ && v->count && v->items[0]->kind == PFX_NODE_MAP)) {
        double x;
        if (pfx_read_number(r, v, "intensity", &x) &&
            pfx_check_above(r, v, "intensity", x, 0, false) &&
            pfx_check_below(r, v, "intensity", x, PFX_HDR_MAX, false))
            look->intensity = (float)x;
        return;
    }
    look->intensity_curve =
        pfx_read_life_curve(r, v, "intensity", 0, PFX_HDR_MAX, look->intensity_lut);
}

/* A ribbon is a strip through points, not a sprite per point: the keys
 * that place, turn, play a sheet on or light a sprite have nothing to act
 * on (a texture spans the whole strip), and
 * its cross-section is round (soft edges) or square (flat). Said at the key
 * rather than ignored, so a file never means more than it draws. */
static void check_ribbon(pfx_reader *r, const pfx_node *n, const pfx_look *look) {
    static const char *const sprite_only[] = {"normal_map", "flipbook", "align", "axis", "normal",
                                              "stretch",    "lit",      "angle", "spin"};
    const pfx_node *v;
    for (size_t i = 0; i < sizeof sprite_only / sizeof *sprite_only; i++)
        if ((v = pfx_node_get(n, sprite_only[i])))
            pfx_read_error(r, v, PFX_RULE_INAPPLICABLE_KEY,
                           "'%s' does not apply to draw: ribbon (a strip, not sprites)",
                           sprite_only[i]);
    if (look->sprite != PFX_SPRITE_ROUND && look->sprite != PFX_SPRITE_SQUARE)
        pfx_read_error(r, pfx_node_get(n, "sprite"), PFX_RULE_UNKNOWN_CHOICE,
                       "a ribbon's cross-section is 'round' (soft) or 'square' (flat), got '%s'",
                       pfx_kind_name(pfx_sprite_names, (int)look->sprite));
}

void pfx_compile_look(pfx_reader *r, const pfx_node *n, pfx_emitter *em, const char *effect_path) {
    pfx_look *look = &em->look;
    const pfx_node *v;
    if (look->draw == PFX_DRAW_RIBBON) {
        check_ribbon(r, n, look);
        if ((v = pfx_node_get(n, "texture"))) /* once along the strip (render/shader.c) */
            look->texture = read_texture(r, v, "texture", effect_path, true);
        if ((v = pfx_node_get(n, "intensity")))
            read_intensity(r, v, look);
        return;
    }
    if ((v = pfx_node_get(n, "texture")))
        look->texture = read_texture(r, v, "texture", effect_path, true);
    if ((v = pfx_node_get(n, "normal_map")))
        look->normal_map = read_texture(r, v, "normal_map", effect_path, false);
    if ((v = pfx_node_get(n, "flipbook")))
        check_flipbook(r, v, look);
    if (look->align == PFX_ALIGN_AXIS || look->align == PFX_ALIGN_WORLD)
        read_align_vector(r, n, look);
    else if ((v = pfx_node_get(n, "axis")))
        pfx_read_error(r, v, PFX_RULE_INAPPLICABLE_KEY, "'axis' needs align: axis");
    else if ((v = pfx_node_get(n, "normal")))
        pfx_read_error(r, v, PFX_RULE_INAPPLICABLE_KEY, "'normal' needs align: world");
    if ((v = pfx_node_get(n, "ribbon")))
        pfx_read_error(r, v, PFX_RULE_INAPPLICABLE_KEY, "'ribbon' needs draw: ribbon");
    if ((v = pfx_node_get(n, "stretch")) && look->align != PFX_ALIGN_VELOCITY)
        pfx_read_error(r, v, PFX_RULE_INAPPLICABLE_KEY, "'stretch' needs align: velocity");
    if ((v = pfx_node_get(n, "intensity")))
        read_intensity(r, v, look);
    /* Smoke, dust and cloud sheets have no up, and a field of them all at
     * one angle repeats visibly: the built-in smoke puff and alpha-blended
     * textures facing the camera take a random turn unless `angle` is set.
     * Additive textures (flames that rise, sparks), the symmetric built-in
     * shapes, square, and aligned sprites keep angle 0. */
    look->random_angle =
        !pfx_node_get(n, "angle") && look->align == PFX_ALIGN_CAMERA &&
        (look->sprite == PFX_SPRITE_SMOKE || (look->texture && em->blend == PFX_BLEND_ALPHA));
    if (look->normal_map && !look->lit)
        pfx_read_warning(r, pfx_node_get(n, "normal_map"), PFX_RULE_INEFFECTIVE_SETTING,
                         "emitter '%s' has a normal map but is not lit: add lit: true", em->name);
}
