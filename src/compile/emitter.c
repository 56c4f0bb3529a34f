/* One emitter: its key table, the defaults of an empty emitter, and the
 * keys that need code (where and how it emits, the forces and deflectors it
 * names, its kill rules, how it moves). The keys of a group (shape,
 * emission, appearance, sub-emitters) are read by their own files. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "compile/compile_appearance.h"
#include "compile/compile_emission.h"
#include "compile/compile_kill.h"
#include "compile/compile_look.h"
#include "compile/compile_shape.h"
#include "compile/compile_spawn.h"
#include "compile/compiler.h"

static int read_enum(compiler *c, const pfx_node *n, const char *key, const char *what,
                     const char *const *names) {
    return pfx_read_enum(&c->r, n, key, what, names);
}

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

static void normalize3(double v[3]) {
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int i = 0; i < 3; i++)
        v[i] /= len;
}

static void read_integrator(compiler *c, const pfx_node *n, pfx_integrator *out) {
    int i = read_enum(c, n, "integrator", "integrator", pfx_integrator_names);
    if (i >= 0)
        *out = (pfx_integrator)i;
}

#define M(field) offsetof(pfx_emitter, field)

/* Every key of an emitter. The typed rows (speed, lifetime, ...) are read
 * by the table; the others by the code below and the group files, in the
 * order their dependencies need (shape before lod, colour before kill,
 * forces before the motion). */
static const pfx_key emitter_keys[] = {
    {"shape", PFX_KEY_CODE,
     .schema = "{\"$ref\": \"#/$defs/shape\", \"default\": {\"type\": \"point\"}}", .offset = -1,
     .doc = "Where particles are born: point, line, rect, disc, ellipse, box, sphere, hemisphere, "
            "cylinder, cone or mesh."},
    {"position", PFX_KEY_CODE,
     .schema = "{\"default\": [0, 0, 0], \"oneOf\": [{\"$ref\": \"#/$defs/vec3\"}, "
               "{\"description\": \"Keyframes [{t, value}], 1 to 256, t strictly increasing "
               "(effect seconds); linear between keys, held before the first and after the "
               "last.\", \"type\": \"array\", \"minItems\": 1, \"maxItems\": 256, \"items\": "
               "{\"description\": \"A keyframe.\", \"type\": \"object\", \"additionalProperties\": "
               "false, \"properties\": {\"t\": {\"description\": \"Effect time in seconds.\", "
               "\"type\": \"number\"}, \"value\": {\"$ref\": \"#/$defs/vec3\", \"description\": "
               "\"The vector at t.\"}}, \"required\": [\"t\", \"value\"]}}]}",
     .offset = -1,
     .doc = "The emitter's centre in the world (metres), or keyframes [{t, value}]; for a "
            "sub-emitter's target, an offset from the parent particle."},
    {"rotation", PFX_KEY_CODE,
     .schema = "{\"default\": [0, 0, 0], \"oneOf\": [{\"$ref\": \"#/$defs/vec3\"}, "
               "{\"description\": \"Keyframes [{t, value}], 1 to 256, t strictly increasing "
               "(effect seconds); linear between keys, held before the first and after the "
               "last.\", \"type\": \"array\", \"minItems\": 1, \"maxItems\": 256, \"items\": "
               "{\"description\": \"A keyframe.\", \"type\": \"object\", \"additionalProperties\": "
               "false, \"properties\": {\"t\": {\"description\": \"Effect time in seconds.\", "
               "\"type\": \"number\"}, \"value\": {\"$ref\": \"#/$defs/vec3\", \"description\": "
               "\"The vector at t.\"}}, \"required\": [\"t\", \"value\"]}}]}",
     .offset = -1,
     .doc = "Degrees about X, then Y, then Z (fixed axes: R = Rz Ry Rx), or keyframes [{t, "
            "value}]; turns the shape and the direction."},
    {"rate", PFX_KEY_CODE, .schema = "{\"$ref\": \"#/$defs/rate\"}", .offset = -1,
     .doc = "Births per second: a number, {mean, var}, {initial, delta} or a curve [{t, value}] "
            "(see the rate definition)."},
    {"interval", PFX_KEY_CODE,
     .schema = "{\"$ref\": \"#/$defs/value\", \"minimum\": 0.0001, \"items\": {\"minimum\": "
               "0.0001}, \"properties\": {\"mean\": {\"minimum\": 0.0001}, \"clamp\": {\"items\": "
               "{\"minimum\": 0.0001}}}}",
     .offset = -1,
     .doc = "Seconds between births (a value drawn per birth; its smallest sample at least 1e-4), "
            "instead of rate."},
    {"bursts", PFX_KEY_CODE,
     .schema = "{\"type\": \"array\", \"maxItems\": 256, \"items\": {\"$ref\": \"#/$defs/burst\"}}",
     .offset = -1, .doc = "Bursts in order of time (at most 256)."},
    {"start", PFX_KEY_NUMBER, .lo = 0, .hi = INFINITY, .def = {0}, .offset = -1,
     .doc = "Effect time in seconds the emitter starts, at least 0."},
    {"duration", PFX_KEY_NUMBER, PFX_KEY_LO_STRICT | PFX_KEY_NO_DEFAULT, .lo = 0, .hi = INFINITY,
     .offset = -1,
     .doc = "Seconds it emits after its start (default: for ever); its period when it loops. Above "
            "0."},
    {"loop", PFX_KEY_BOOL, .def = {0}, .offset = -1,
     .doc = "Repeat the emission pattern every 'duration' seconds (needs duration)."},
    {"direction", PFX_KEY_CODE,
     .schema = "{\"default\": [0, 1, 0], \"oneOf\": [{\"$ref\": \"#/$defs/vec3\", \"not\": "
               "{\"items\": {\"const\": 0}}}, {\"enum\": [\"normal\", \"radial\", \"inward\", "
               "\"tangent\"]}]}",
     .offset = -1,
     .doc = "The axis particles leave along, in the emitter's frame: a vector (not [0, 0, 0]), or "
            "normal (the shape's outward normal at the birth point), radial (away from the shape's "
            "centre), inward, or tangent (about the shape's Y axis, counter-clockwise seen from "
            "+Y: swirls and portals)."},
    {"spread", PFX_KEY_CODE,
     .schema =
         "{\"default\": 0, \"oneOf\": [{\"description\": \"Half-angle in degrees, 0 to 180.\", "
         "\"type\": \"number\", \"minimum\": 0, \"maximum\": 180}, {\"description\": \"[alpha, "
         "beta] in degrees, each 0 to 360.\", \"type\": \"array\", \"items\": {\"type\": "
         "\"number\", \"minimum\": 0, \"maximum\": 360}, \"minItems\": 2, \"maxItems\": 2}]}",
     .offset = -1,
     .doc = "Cone half-angle in degrees around the direction, 0 to 180 (uniform over the cap), or "
            "the two angles [alpha, beta], each 0 to 360 (uniform turns in +-alpha/2 about Z, then "
            "+-beta/2 about X)."},
    {"distance", PFX_KEY_VALUE, .lo = -1e6, .hi = 1e6, .def = {0}, .offset = M(distance),
     .doc = "Birth offset in metres along the particle's direction, -1e6 to 1e6."},
    {"inherit_velocity", PFX_KEY_NUMBER, .lo = -100, .hi = 100, .def = {0},
     .offset = M(inherit_velocity),
     .doc = "Fraction of the moving emitter's velocity (from its position keyframes) added at "
            "birth, -100 to 100."},
    {"speed", PFX_KEY_VALUE, .lo = -1e6, .hi = 1e6, .def = {1}, .offset = M(speed),
     .doc = "Speed at birth in m/s, -1e6 to 1e6."},
    {"lifetime", PFX_KEY_VALUE, PFX_KEY_LO_STRICT, .lo = 0, .hi = MAX_SECONDS, .def = {1},
     .offset = M(lifetime), .doc = "Seconds a particle lives, greater than 0, at most 86400."},
    {"size", PFX_KEY_CODE,
     .schema =
         "{\"default\": 0.1, \"oneOf\": [{\"description\": \"A size that stays the same over "
         "life.\", \"$ref\": \"#/$defs/value\", \"minimum\": 0, \"maximum\": 1000000, \"items\": "
         "{\"minimum\": 0, \"maximum\": 1000000}, \"properties\": {\"mean\": {\"minimum\": 0, "
         "\"maximum\": 1000000}, \"clamp\": {\"items\": {\"minimum\": 0, \"maximum\": 1000000}}}}, "
         "{\"$ref\": \"#/$defs/size_start_end\"}, {\"description\": \"Size over normalised age, 1 "
         "to 64 keys.\", \"type\": \"array\", \"minItems\": 1, \"maxItems\": 64, \"items\": "
         "{\"description\": \"A key: the value at age fraction 'at'.\", \"type\": \"object\", "
         "\"additionalProperties\": false, \"properties\": {\"at\": {\"description\": \"Age "
         "fraction from 0 (birth) to 1 (death), in increasing order.\", \"type\": \"number\", "
         "\"minimum\": 0, \"maximum\": 1}, \"value\": {\"description\": \"The value at this "
         "age.\", \"type\": \"number\", \"minimum\": 0, \"maximum\": 1000000}}, \"required\": "
         "[\"at\", \"value\"]}}]}",
     .offset = -1,
     .doc = "Sprite diameter in metres, 0 to 1e6: a value, {start, end} (linear over life), or a "
            "curve [{at, value}] over normalised age."},
    {"color", PFX_KEY_CODE,
     .schema = "{\"default\": \"#ffffff\", \"oneOf\": [{\"$ref\": \"#/$defs/gradient\"}, "
               "{\"description\": \"A random mix of two colours, fixed per particle.\", \"type\": "
               "\"object\", \"additionalProperties\": false, \"properties\": {\"random\": "
               "{\"description\": \"[c1, c2]: two colours.\", \"type\": \"array\", \"minItems\": "
               "2, \"maxItems\": 2, \"prefixItems\": [{\"$ref\": \"#/$defs/hdr_colour\", \"not\": "
               "{\"const\": \"transparent\"}}, {\"$ref\": \"#/$defs/hdr_colour\"}], \"items\": "
               "false}}, \"required\": [\"random\"]}, {\"description\": \"A random point of the "
               "gradient, fixed per particle.\", \"type\": \"object\", \"additionalProperties\": "
               "false, \"properties\": {\"pick\": {\"$ref\": \"#/$defs/gradient\", "
               "\"description\": \"The gradient picked from.\"}}, \"required\": [\"pick\"]}]}",
     .offset = -1,
     .doc =
         "Colour or gradient over life (by age / lifetime), {random: [c1, c2]} (a fixed random mix "
         "per particle) or {pick: gradient} (a fixed random point of the gradient per particle)."},
    {"alpha", PFX_KEY_CODE,
     .schema =
         "{\"default\": 1, \"oneOf\": [{\"description\": \"Constant alpha factor, 0 to 1.\", "
         "\"type\": \"number\", \"minimum\": 0, \"maximum\": 1}, {\"description\": \"Linear from "
         "start to end.\", \"type\": \"object\", \"additionalProperties\": false, \"properties\": "
         "{\"start\": {\"description\": \"At birth, 0 to 1.\", \"type\": \"number\", \"minimum\": "
         "0, \"maximum\": 1, \"default\": 1}, \"end\": {\"description\": \"At death, 0 to 1.\", "
         "\"type\": \"number\", \"minimum\": 0, \"maximum\": 1, \"default\": 1}}}, "
         "{\"description\": \"Alpha over normalised age, 1 to 64 keys.\", \"type\": \"array\", "
         "\"minItems\": 1, \"maxItems\": 64, \"items\": {\"description\": \"A key: the value at "
         "age fraction 'at'.\", \"type\": \"object\", \"additionalProperties\": false, "
         "\"properties\": {\"at\": {\"description\": \"Age fraction from 0 (birth) to 1 (death), "
         "in increasing order.\", \"type\": \"number\", \"minimum\": 0, \"maximum\": 1}, "
         "\"value\": {\"description\": \"The value at this age.\", \"type\": \"number\", "
         "\"minimum\": 0, \"maximum\": 1}}, \"required\": [\"at\", \"value\"]}}]}",
     .offset = -1,
     .doc = "Opacity multiplier over life, 0 to 1: a number, {start, end} (linear) or a curve "
            "[{at, value}]."},
    {"angle", PFX_KEY_VALUE, .lo = -INFINITY, .hi = INFINITY, .def = {0}, .offset = -1,
     .doc = "Sprite angle at birth in degrees (a value). Without it smoke sprites and alpha "
            "textures facing the camera turn at random, other sprites stay at 0."},
    {"spin", PFX_KEY_CODE,
     .schema =
         "{\"default\": 0, \"oneOf\": [{\"$ref\": \"#/$defs/value\"}, {\"type\": \"array\", "
         "\"minItems\": 1, \"maxItems\": 64, \"items\": {\"type\": \"object\", "
         "\"additionalProperties\": false, \"required\": [\"at\", \"value\"], \"properties\": "
         "{\"at\": {\"type\": \"number\", \"minimum\": 0, \"maximum\": 1}, \"value\": {\"type\": "
         "\"number\", \"minimum\": -1000000, \"maximum\": 1000000}}}}]}",
     .offset = -1,
     .doc = "Sprite turn rate in degrees per second: a value per particle, or a curve [{at, "
            "value}] over normalised age."},
    {"draw", PFX_KEY_ENUM, .names = pfx_draw_names, .def = {0}, .offset = M(look.draw),
     .what = "draw mode",
     .doc = "sprite: one sprite per particle; ribbon: for an emitter fed by a trail, each "
            "parent's trail particles joined in birth order (and on to the parent while it "
            "lives) into one strip facing the camera "
            "(width from size, colour and alpha over life of each point; sprite: round gives soft "
            "edges, square flat ones)."},
    {"sprite", PFX_KEY_ENUM, .names = pfx_sprite_names, .def = {0}, .offset = M(look.sprite),
     .what = "sprite shape",
     .doc = "The built-in sprite: round (soft disc), square (soft square that turns with angle "
            "and spin), spark (bright core, long falloff), smoke (a noise puff, each particle its "
            "own), flare (a star with a soft halo) or ring."},
    {"texture", PFX_KEY_CODE, .offset = -1, .schema = "{\"type\": \"string\"}",
     .doc = "A PNG (grey, grey + alpha, RGB or RGBA; 8 or 16 bits; at most 8192x8192) relative "
            "to the effect file, instead of the built-in sprite: its alpha is the shape, the "
            "particle's colour multiplies it; on a ribbon it spans the strip once, left edge at "
            "the head."},
    {"normal_map", PFX_KEY_CODE, .offset = -1, .schema = "{\"type\": \"string\"}",
     .doc = "A PNG of tangent-space normals (RGB = (n + 1) / 2, +y up the image) for lit sprites, "
            "instead of the spherical normal."},
    {"flipbook", PFX_KEY_MAP, .offset = M(look.flipbook), .table = &pfx_flipbook_table,
     .doc = "Play the texture as a sheet of cells over the particle's age."},
    {"align", PFX_KEY_ENUM, .names = pfx_align_names, .def = {0}, .offset = M(look.align),
     .what = "alignment",
     .doc = "camera (faces the camera), velocity (stretched along the screen-space velocity), "
            "axis (turns about the world axis 'axis' to face the camera) or world (lies in the "
            "plane with normal 'normal')."},
    {"axis", PFX_KEY_VEC3, PFX_KEY_NONZERO, .def = {0, 1, 0}, .offset = -1,
     .doc = "align: axis: the world axis the sprite's height follows (any length)."},
    {"normal", PFX_KEY_VEC3, PFX_KEY_NONZERO, .def = {0, 1, 0}, .offset = -1,
     .doc = "align: world: the normal of the plane the sprite lies in (any length)."},
    {"stretch", PFX_KEY_MAP, .offset = M(look), .table = &pfx_stretch_table,
     .doc = "align: velocity: length = size x length + |v| x speed."},
    {"ribbon", PFX_KEY_MAP, .offset = M(look), .table = &pfx_ribbon_table,
     .doc = "draw: ribbon: taper: [head, tail], the fractions of its length over which the strip "
            "narrows and fades to 0 at each end."},
    {"lit", PFX_KEY_BOOL, .def = {0}, .offset = M(look.lit),
     .doc = "Shade by the effect's light with a spherical normal per sprite (or normal_map); "
            "for alpha sprites such as smoke."},
    {"intensity", PFX_KEY_CODE, .offset = -1,
     .schema = "{\"default\": 1, \"oneOf\": [{\"type\": \"number\", \"minimum\": 0, "
               "\"maximum\": 1000}, {\"type\": \"array\", \"minItems\": 1, \"maxItems\": 64, "
               "\"items\": {\"type\": \"object\", \"additionalProperties\": false, "
               "\"required\": [\"at\", \"value\"], \"properties\": {\"at\": {\"type\": "
               "\"number\", \"minimum\": 0, \"maximum\": 1}, \"value\": {\"type\": "
               "\"number\", \"minimum\": 0, \"maximum\": 1000}}}}]}",
     .doc = "Multiplies the colour (not alpha), 0 to 1000, for HDR light: a number or a curve "
            "[{at, value}] over normalised age."},
    {"forces", PFX_KEY_CODE, .schema = "{\"type\": \"array\", \"items\": {\"type\": \"string\"}}",
     .offset = -1,
     .doc = "Names of the forces this emitter feels; default: every force; [] for none."},
    {"deflectors", PFX_KEY_CODE,
     .schema = "{\"type\": \"array\", \"items\": {\"type\": \"string\"}}", .offset = -1,
     .doc = "Names of the deflectors this emitter's particles hit; default: every deflector; [] "
            "for none."},
    {"gravity_scale", PFX_KEY_VALUE, .lo = -1e3, .hi = 1e3, .def = {1}, .offset = M(gravity_scale),
     .doc = "Per-particle multiplier of the gravity felt, -1000 to 1000."},
    {"charge", PFX_KEY_VALUE, .lo = -1e6, .hi = 1e6, .def = {1}, .offset = M(charge),
     .doc = "Per-particle charge in coulombs for magnetic forces, -1e6 to 1e6."},
    {"mass", PFX_KEY_VALUE, PFX_KEY_LO_STRICT, .lo = 0, .hi = 1e6, .def = {1}, .offset = M(mass),
     .doc = "Per-particle mass in kilograms for magnetic forces, above 0, at most 1e6 (other "
            "forces are per unit mass)."},
    {"on_birth", PFX_KEY_CODE,
     .schema = "{\"oneOf\": [{\"$ref\": \"#/$defs/spawn\"}, {\"type\": \"array\", \"items\": "
               "{\"$ref\": \"#/$defs/spawn\"}, \"minItems\": 1, \"maxItems\": 16}]}",
     .offset = -1, .doc = "Sub-emitters fired when a particle is born."},
    {"on_death", PFX_KEY_CODE,
     .schema = "{\"oneOf\": [{\"$ref\": \"#/$defs/spawn\"}, {\"type\": \"array\", \"items\": "
               "{\"$ref\": \"#/$defs/spawn\"}, \"minItems\": 1, \"maxItems\": 16}]}",
     .offset = -1,
     .doc = "Sub-emitters fired when a particle dies (of age, a kill rule, or a kill deflector)."},
    {"on_hit", PFX_KEY_CODE,
     .schema = "{\"oneOf\": [{\"$ref\": \"#/$defs/spawn\"}, {\"type\": \"array\", \"items\": "
               "{\"$ref\": \"#/$defs/spawn\"}, \"minItems\": 1, \"maxItems\": 16}]}",
     .offset = -1,
     .doc =
         "Sub-emitters fired at each deflector impact, at the hit point with the surface normal."},
    {"trail", PFX_KEY_CODE,
     .schema = "{\"oneOf\": [{\"$ref\": \"#/$defs/trail\"}, {\"type\": \"array\", \"items\": "
               "{\"$ref\": \"#/$defs/trail\"}, \"minItems\": 1, \"maxItems\": 16}]}",
     .offset = -1, .doc = "Trails: particles made along each particle's path at a rate."},
    {"lod", PFX_KEY_CODE,
     .schema =
         "{\"type\": \"object\", \"additionalProperties\": false, \"properties\": {\"per_pixel\": "
         "{\"description\": \"Mean births per second per pixel of screen area, 0 to 1e6.\", "
         "\"type\": \"number\", \"minimum\": 0, \"maximum\": 1000000, \"default\": 1}, \"var\": "
         "{\"description\": \"Half-width of the random per-pixel rate, 0 to 1e6.\", \"type\": "
         "\"number\", \"minimum\": 0, \"maximum\": 1000000, \"default\": 0}}}",
     .offset = -1,
     .doc = "Level of detail (Reeves): births per second = (per_pixel + R var) x the emitter's "
            "area on screen in pixels; instead of rate."},
    {"integrator", PFX_KEY_ENUM, .names = pfx_integrator_names, .def = {0}, .offset = -1,
     .doc = "This emitter's integrator, overriding sim.integrator."},
    {"kill", PFX_KEY_CODE,
     .schema =
         "{\"type\": \"array\", \"maxItems\": 16, \"items\": {\"$ref\": \"#/$defs/kill_rule\"}}",
     .offset = -1, .doc = "Kill rules (at most 16), applied after each step."},
    {"bounds", PFX_KEY_CODE,
     .schema = "{\"type\": \"object\", \"additionalProperties\": false, \"properties\": {\"box\": "
               "{\"$ref\": \"#/$defs/kill_box\"}, \"mode\": {\"description\": \"kill (default) or "
               "wrap.\", \"enum\": [\"kill\", \"wrap\"], \"default\": \"kill\"}}, \"required\": "
               "[\"box\"], \"if\": {\"required\": [\"mode\"], \"properties\": {\"mode\": "
               "{\"const\": \"wrap\"}}}, \"then\": {\"properties\": {\"box\": {\"properties\": "
               "{\"size\": {\"items\": {\"exclusiveMinimum\": 0}}}}}}}",
     .offset = -1,
     .doc = "A box the particles stay in: mode kill removes those outside, wrap brings them back "
            "in at the opposite face."},
    {"blend", PFX_KEY_ENUM, .def = {0}, .offset = M(blend), .names = pfx_blend_names,
     .what = "blend mode",
     .doc = "add: light adds, hides nothing; alpha: covers what is behind, sorted back to front."},
    {"motion_vectors", PFX_KEY_BOOL, .def = {1}, .offset = M(motion_vectors),
     .doc = "false: leave this emitter out of the --motion-vectors pass (its pixels read no "
            "motion) and out of the choice of its scale."},
};
const pfx_key_table pfx_emitter_table = {
    "emitter",
    "A named emitter. Every key is optional; {} is a point emitting 10 white 0.1 m particles a "
    "second straight up at 1 m/s for 1 s, additive.",
    NULL, emitter_keys, sizeof emitter_keys / sizeof emitter_keys[0],
    /* rules across keys: rate, interval and lod exclude each other, ... */
    "{\"allOf\": [{\"not\": {\"required\": [\"rate\", \"interval\"]}}, {\"not\": {\"required\": "
    "[\"l"
    "od\", \"rate\"]}}, {\"not\": {\"required\": [\"lod\", \"interval\"]}}, {\"if\": "
    "{\"required\": "
    "[\"loop\"], \"properties\": {\"loop\": {\"const\": true}}}, \"then\": {\"required\": [\"durat"
    "ion\"]}}]}"};

/* An emitter's `deflectors: [names]` (default: all of them), copied into
 * the emitter so the collision pass reads one dense array. */
static void emitter_deflectors(compiler *c, const pfx_node *n, pfx_emitter *em) {
    const pfx_effect *e = c->e;
    const pfx_node *v = pfx_node_get(n, "deflectors");
    bool use[PFX_MAX_DEFLECTORS] = {0};
    for (size_t i = 0; i < e->deflector_count; i++)
        use[i] = !v;
    if (v && v->kind != PFX_NODE_SEQ) {
        pfx_read_error(&c->r, v, PFX_RULE_WRONG_TYPE,
                       "'deflectors' must be a list of deflector names, got %s",
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
                pfx_read_error(&c->r, v->items[i], PFX_RULE_UNKNOWN_NAME,
                               "unknown deflector '%s' in emitter '%s'; did you mean '%s'?", name,
                               em->name, sug);
            else
                pfx_read_error(&c->r, v->items[i], PFX_RULE_UNKNOWN_NAME,
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
                pfx_read_warning(&c->r, kill_node, PFX_RULE_DIES_AT_BIRTH,
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
        pfx_read_error(&c->r, v, PFX_RULE_CONFLICTING_KEYS,
                       "'lod' sets the rate from the screen area; drop 'rate'");
        return;
    }
    double per_pixel = 1, var = 0;
    opt_number(c, v, "per_pixel", &per_pixel, 0, false, 1e6);
    opt_number(c, v, "var", &var, 0, false, 1e6);
    double pixels_per_metre =
        pfx_camera_pixels_per_metre(&c->e->camera, c->e->height, em->position);
    double r_px = shape_radius(&em->shape) * pixels_per_metre;
    em->lod_area = fmax(1.0, M_PI * r_px * r_px);
    em->rate_kind = var > 0 ? PFX_RATE_RANDOM : PFX_RATE_CONSTANT;
    em->rate = fmin(per_pixel * em->lod_area, 1e7);
    em->rate_var = fmin(var * em->lod_area, em->rate);
}

/* `direction` (a vector, or normal | radial | inward | tangent), `spread` (a cone
 * half-angle, or the thesis's [alpha, beta]), `distance` and
 * `inherit_velocity`. The direction stays in the emitter's frame: the
 * emitter's rotation at each birth turns it. */
static void compile_direction(compiler *c, const pfx_node *n, pfx_emitter *em) {
    const pfx_node *v;
    double dir[3] = {0, 1, 0};
    if ((v = pfx_node_get(n, "direction"))) {
        if (v->kind == PFX_NODE_SCALAR) {
            int m = read_enum(c, v, "direction", "direction", pfx_direction_mode_names);
            if (m >= 0)
                em->direction_mode = (pfx_direction_mode)(m + 1);
        } else if (pfx_read_numbers(&c->r, v, "direction", dir, 3) && dir[0] == 0 && dir[1] == 0 &&
                   dir[2] == 0) {
            pfx_read_error(&c->r, v, PFX_RULE_ZERO_VECTOR,
                           "'direction' must not be the zero vector");
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
                em->spread_alpha = ab[0] * PFX_DEGREE;
                em->spread_beta = ab[1] * PFX_DEGREE;
            }
        } else {
            double deg = 0;
            opt_number(c, n, "spread", &deg, 0, false, 180);
            em->spread = deg * M_PI / 180.0;
        }
    }
}

/* force_over_life as this emitter feels it. In the emitter's space a fixed
 * rotation turns the keys once, here; a keyframed one turns them at every
 * step (f->frame). jerk_hint is the steepest |da/dt| = |da/du| / lifetime
 * at the shortest lifetime: auto's error model reads it. */
static void fit_life_force(compiler *c, const pfx_emitter *em, pfx_motion_force *f) {
    const pfx_life_curve *in = f->life;
    if (!in)
        return;
    if (f->space == PFX_SPACE_EMITTER && em->rotation_keys.count > 1) {
        f->frame = em;
    } else if (f->space == PFX_SPACE_EMITTER) {
        pfx_life_curve *turned = pfx_arena_alloc(c->r.arena, sizeof *turned);
        if (!turned)
            return;
        *turned = *in;
        const double *m = em->rotation;
        for (size_t k = 0; k < in->count; k++)
            for (int a = 0; a < 3; a++)
                turned->accel[k][a] = m[3 * a] * in->accel[k][0] + m[3 * a + 1] * in->accel[k][1] +
                                      m[3 * a + 2] * in->accel[k][2];
        f->life = turned;
    }
    double slope = 0;
    for (size_t k = 0; k + 1 < in->count; k++) {
        double du = in->at[k + 1] - in->at[k], d[3];
        for (int a = 0; a < 3; a++)
            d[a] = in->accel[k + 1][a] - in->accel[k][a];
        if (du > 0)
            slope = fmax(slope, sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / du);
    }
    double life = pfx_value_min(&em->lifetime);
    f->jerk_hint = slope > 0 ? slope / fmax(life, 1e-9) : 0;
}

/* auto's tolerance, m per simulated second. Given in pixels: the pixels
 * as metres at the emitter's depth (pfx_camera_pixels_per_metre), over its
 * longest lifetime, since auto's error grows with age at that rate; an
 * emitter at or behind the camera keeps the default 1e-3 m/s. */
static double motion_tolerance(const pfx_effect *e, const pfx_emitter *em) {
    if (!(e->tolerance_px > 0))
        return e->tolerance;
    double ppm = pfx_camera_pixels_per_metre(&e->camera, e->height, em->position);
    if (!(ppm > 0))
        return 1e-3;
    return fmax(e->tolerance_px / ppm / fmax(em->max_lifetime, 1e-3), 1e-12);
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
    m->tolerance = motion_tolerance(e, em);
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
        if (f->kind == PFX_MOTION_FORCE_OVER_LIFE)
            fit_life_force(c, em, f);
    }
    pfx_motion_choose(m, 1.0 / e->sim_rate);
    em->motion = m;
    pfx_stability_warning w[8];
    size_t n = pfx_motion_check_stability(m, w, 8);
    for (size_t i = 0; i < n && i < 8; i++)
        pfx_read_warning(&c->r, at, PFX_RULE_UNSTABLE_INTEGRATOR, "emitter '%s': %s", em->name,
                         w[i].message);
    const double tol = m->tolerance > 0 ? m->tolerance : 1e-3;
    if (integrator == PFX_INTEGRATOR_AUTO && m->substeps == 0 && m->choice.error_rate > tol)
        pfx_read_warning(&c->r, at, PFX_RULE_UNSTABLE_INTEGRATOR,
                         "emitter '%s': auto cannot keep the tolerance of %g m/s: even %d "
                         "substeps leave an expected error of %.2g m/s; raise sim.rate",
                         em->name, tol, m->choice.steps, m->choice.error_rate);
}

/* Defaults: a point emitting 10/s straight up at 1 m/s for 1 s, white,
 * 0.1 m sprites, additive, feeling every force, not turned. */
static void emitter_defaults(const pfx_effect *e, pfx_emitter *em) {
    pfx_keys_defaults(&pfx_emitter_table, em);
    em->direction[1] = 1;
    em->size_start = em->size_end = pfx_value_const(0.1);
    em->size_same = true;
    for (int i = 0; i < PFX_GRADIENT_LUT; i++)
        for (int k = 0; k < 4; k++)
            em->color.lut[i][k] = 1.0f;
    em->color.constant = true;
    em->look.intensity = 1;
    em->force_mask = e->force_count >= 32 ? 0xffffffffu : (1u << e->force_count) - 1;
    const double no_rotation[3] = {0, 0, 0};
    pfx_rotation_from_angles(no_rotation, em->rotation);
}

/* `rotation`: Euler angles written in degrees, constant or keyed; the
 * model holds radians. */
static void emitter_rotation(compiler *c, const pfx_node *v, pfx_emitter *em) {
    double rot[3] = {0, 0, 0};
    if (!pfx_read_keys3(&c->r, v, "rotation", rot, &em->rotation_keys))
        return;
    for (int a = 0; a < 3; a++)
        rot[a] *= PFX_DEGREE;
    for (size_t k = 0; k < em->rotation_keys.count; k++)
        for (int a = 0; a < 3; a++)
            em->rotation_keys.v[k][a] *= PFX_DEGREE;
    pfx_rotation_from_angles(rot, em->rotation);
}

/* `forces`: the names of the top-level forces this emitter feels. */
static void emitter_forces(compiler *c, const pfx_node *v, const pfx_node *key, pfx_emitter *em) {
    const pfx_effect *e = c->e;
    em->force_mask = 0;
    if (v->kind != PFX_NODE_SEQ) {
        pfx_read_error(&c->r, v, PFX_RULE_WRONG_TYPE,
                       "'forces' must be a list of force names, got %s", pfx_node_kind_name(v));
        return;
    }
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
            pfx_read_error(&c->r, v->items[i], PFX_RULE_UNKNOWN_NAME,
                           "unknown force '%s' in emitter '%s'; did you mean '%s'?", name,
                           key->text, sug);
        else
            pfx_read_error(&c->r, v->items[i], PFX_RULE_UNKNOWN_NAME,
                           "unknown force '%s' in emitter '%s'; define it under 'forces'", name,
                           key->text);
    }
}

void pfx_compile_emitter(compiler *c, const pfx_node *key, const pfx_node *n, pfx_emitter *em) {
    pfx_effect *e = c->e;
    em->name = pfx_arena_strndup(c->r.arena, key->text, key->len);
    emitter_defaults(e, em);

    char where[160];
    snprintf(where, sizeof where, "emitter '%s'", key->text);
    if (!pfx_read_map(&c->r, n, key->text))
        return;
    pfx_keys_check(&c->r, n, &pfx_emitter_table, where);
    pfx_keys_read(&c->r, n, &pfx_emitter_table, em);
    const pfx_node *v;
    if ((v = pfx_node_get(n, "shape")))
        pfx_compile_shape(&c->r, v, &em->shape, em->name, e->path);
    if ((v = pfx_node_get(n, "position")))
        pfx_read_keys3(&c->r, v, "position", em->position, &em->position_keys);
    if ((v = pfx_node_get(n, "rotation")))
        emitter_rotation(c, v, em);
    pfx_compile_emission(&c->r, n, em);
    if ((v = pfx_node_get(n, "lod")))
        compile_lod(c, v, n, em);
    compile_direction(c, n, em);
    em->max_lifetime = pfx_value_max(&em->lifetime);
    pfx_compile_appearance(&c->r, n, em);
    pfx_compile_look(&c->r, n, em, e->path);
    compile_kill(c, n, em);
    if ((v = pfx_node_get(n, "forces")))
        emitter_forces(c, v, key, em);
    emitter_deflectors(c, n, em);
    pfx_integrator integrator = e->integrator;
    const pfx_node *integrator_node = pfx_node_get(n, "integrator");
    if (integrator_node)
        read_integrator(c, integrator_node, &integrator);
    build_motion(c, em, integrator, integrator_node ? integrator_node : key);
    em->size_varies = em->size_start.dist != PFX_DIST_CONST ||
                      (!em->size_same && em->size_end.dist != PFX_DIST_CONST);
}
