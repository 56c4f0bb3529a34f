/* Simulation state -> what the renderer draws: one material per emitter
 * (its look) and one sprite per live particle: size over life, colour from
 * the gradient times intensity, premultiplied, with the occluding alpha set
 * to 0 for additive emitters (see pfx_sprite); the flipbook cell, the
 * particle's own variant, its velocity and stretched length. It decides
 * whether a depth sort is needed: only when some emitter blends by alpha. */
#include "render/sprites.h"

#include <math.h>
#include <stdlib.h>

#include "base/rng.h"

bool pfx_sprites_need_sort(const pfx_effect *e) {
    for (size_t i = 0; i < e->emitter_count; i++)
        if (e->emitters[i].blend == PFX_BLEND_ALPHA && e->emitters[i].look.draw == PFX_DRAW_SPRITE)
            return true;
    return false;
}

/* Only a lit sprite reads the volume; the compiler warns when none is,
 * and the frames would be the same without it. */
bool pfx_sprites_shadowed(const pfx_effect *e) {
    for (size_t i = 0; e->light_shadows && i < e->emitter_count; i++)
        if (e->emitters[i].look.lit && e->emitters[i].look.draw == PFX_DRAW_SPRITE)
            return true;
    return false;
}

size_t pfx_sprites_capacity(const pfx_effect *e) {
    size_t n = 0;
    for (size_t i = 0; i < e->emitter_count; i++)
        n += e->emitters[i].capacity;
    return n;
}

void pfx_sprites_materials(const pfx_effect *e, pfx_material *out) {
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_look *k = &e->emitters[i].look;
        const pfx_flipbook *b = &k->flipbook;
        out[i] = (pfx_material){.sprite = k->sprite,
                                .texture = k->texture,
                                .normal_map = k->normal_map,
                                .cols = b->frames ? b->cols : 1,
                                .rows = b->frames ? b->rows : 1,
                                .frames = b->frames ? b->frames : 1,
                                .frame_loop = b->fps > 0,
                                .frame_blend = b->blend,
                                .align = k->align,
                                .axis = {k->axis[0], k->axis[1], k->axis[2]},
                                .lit = k->lit,
                                .shadowed = k->lit && e->light_shadows};
    }
}

pfx_render_settings pfx_sprites_settings(const pfx_effect *e) {
    pfx_render_settings s = pfx_render_settings_plain(e->background);
    s.exposure = e->exposure;
    s.tonemap = e->tonemap;
    s.preserve_hue = e->preserve_hue;
    s.alpha = e->alpha_mode;
    s.dither = e->dither;
    for (int a = 0; a < 3; a++) {
        s.light_dir[a] = e->light_dir[a];
        s.light_color[a] = e->light_color[a];
        s.ambient[a] = e->light_ambient[a];
    }
    return s;
}

/* A particle's own random in [0, 1), from its emitter and birth index: the
 * same every frame, with no column. */
static float variant_of(size_t emitter, uint32_t id) {
    uint64_t h = pfx_mix64(((uint64_t)emitter << 32) ^ id ^ 0x5bd1e9955bd1e995ULL);
    return (float)((double)(h >> 40) / 16777216.0);
}

/* A second such random, independent of the variant (which also picks the
 * start cell and the smoke puff), for the random turn. */
static double turn_of(size_t emitter, uint32_t id) {
    uint64_t h = pfx_mix64(((uint64_t)emitter << 32) ^ id ^ 0x2545f4914f6cdd1dULL);
    return (double)(h >> 40) / 16777216.0 * 2 * 3.14159265358979323846;
}

/* The flipbook cell (plus the fraction to the next) at normalised age u and
 * age in seconds: `fps` cells per second, looping, or the sheet once over
 * life; from the particle's own start cell when random. */
static float cell_of(const pfx_flipbook *b, float u, double age, float variant) {
    if (!b->frames)
        return 0;
    double start = b->random_start ? floor(variant * b->frames) : 0;
    if (b->fps > 0)
        return (float)fmod(start + age * b->fps, b->frames);
    double f = (u < 0 ? 0 : u) * b->frames;
    if (f > b->frames - 1e-4)
        f = b->frames - 1e-4; /* the last cell at death, not the first again */
    return (float)fmod(start + f, b->frames);
}

/* The sprite of particle j of emitter i (a `draw: sprite` emitter): the
 * same whichever order, chunk or thread asks for it. */
static pfx_sprite sprite_of(const pfx_sim *s, size_t i, uint32_t j) {
    const pfx_emitter *em = &s->effect->emitters[i];
    const pfx_look *k = &em->look;
    const pfx_pool *p = &s->pools[i];
    const bool additive = em->blend == PFX_BLEND_ADD;
    /* A round sprite looks the same at any angle: skip the work. */
    const bool turns =
        k->sprite != PFX_SPRITE_ROUND || k->texture || k->lit || k->align == PFX_ALIGN_WORLD;
    float c[4];
    pfx_particle_color(em, p, j, c);
    const double age = pfx_particle_age(p, j);
    const float u = (float)age / p->lifetime[j], size = pfx_particle_size(em, p, j);
    const float a = c[3], glow = a * pfx_look_intensity(k, u);
    const float variant = variant_of(i, p->id[j]);
    /* What is drawn from motion is the particle's whole motion: its
     * velocity plus what the vortex moves it by (pfx_motion_drift), which
     * the velocity column does not hold. */
    float v[3] = {p->vx[j], p->vy[j], p->vz[j]};
    if (k->align == PFX_ALIGN_VELOCITY && em->motion) {
        double drift[3];
        pfx_motion_drift(em->motion, (const double[3]){p->px[j], p->py[j], p->pz[j]}, drift);
        for (int x = 0; x < 3; x++)
            v[x] = (float)(v[x] + drift[x]);
    }
    const float speed = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    return (pfx_sprite){.x = p->px[j],
                        .y = p->py[j],
                        .z = p->pz[j],
                        .size = size,
                        .r = c[0] * glow,
                        .g = c[1] * glow,
                        .b = c[2] * glow,
                        .a = additive ? 0.0f : a,
                        .angle = (float)((turns ? pfx_particle_angle(em, p, j) : 0) +
                                         (k->random_angle ? turn_of(i, p->id[j]) : 0)),
                        .material = (float)i,
                        .frame = cell_of(&k->flipbook, u, age, variant),
                        .variant = variant,
                        .vx = v[0],
                        .vy = v[1],
                        .vz = v[2],
                        .length =
                            size * (float)k->stretch_length + speed * (float)k->stretch_speed};
}

size_t pfx_sprites_build(const pfx_sim *s, pfx_sprite *out) {
    const pfx_effect *e = s->effect;
    size_t n = 0;
    for (size_t i = 0; i < e->emitter_count; i++)
        if (e->emitters[i].look.draw == PFX_DRAW_SPRITE) /* else ribbons_from_sim.c */
            for (uint32_t j = 0; j < s->pools[i].count; j++)
                out[n++] = sprite_of(s, i, j);
    return n;
}

bool pfx_sprite_feed_init(pfx_sprite_feed *f, const pfx_effect *e) {
    f->sim = NULL;
    f->start = malloc((e->emitter_count + 1) * sizeof *f->start);
    const bool shadowed = pfx_sprites_shadowed(e);
    f->shadow = shadowed ? malloc(sizeof *f->shadow) : NULL;
    return f->start != NULL && (f->shadow || !shadowed);
}

void pfx_sprite_feed_free(pfx_sprite_feed *f) {
    free(f->start);
    free(f->shadow);
    f->start = NULL;
    f->shadow = NULL;
}

/* Casters: every alpha-blended sprite (additive light hides nothing);
 * receivers: the lit ones. Each a sphere of its sprite's radius. */
const pfx_shadow_volume *pfx_sprite_feed_shadow(pfx_sprite_feed *f, const pfx_sim *s) {
    const pfx_effect *e = s->effect;
    pfx_shadow_volume *v = f->shadow;
    if (!v)
        return NULL;
    pfx_shadow_begin(v, e->light_dir);
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1)
            pfx_shadow_frame(v);
        for (size_t i = 0; i < e->emitter_count; i++) {
            const pfx_emitter *em = &e->emitters[i];
            const bool casts = em->blend == PFX_BLEND_ALPHA;
            if (em->look.draw != PFX_DRAW_SPRITE || !(casts || em->look.lit) || (pass && !casts))
                continue;
            const pfx_pool *p = &s->pools[i];
            for (uint32_t j = 0; j < p->count; j++) {
                const float at[3] = {p->px[j], p->py[j], p->pz[j]};
                const float r = 0.5f * pfx_particle_size(em, p, j);
                if (pass == 0) {
                    pfx_shadow_bound(v, at, r);
                } else {
                    float c[4];
                    pfx_particle_color(em, p, j, c);
                    pfx_shadow_splat(v, at, r, (float)(c[3] * e->shadow_density));
                }
            }
        }
    }
    pfx_shadow_finish(v);
    return v;
}

/* The last i with start[i] <= n (emitters without sprites have start[i] =
 * start[i + 1]). */
size_t pfx_sprite_feed_emitter(const pfx_sprite_feed *f, size_t n) {
    size_t lo = 0, hi = f->sim->effect->emitter_count; /* start[lo] <= n < start[hi] */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (f->start[mid] <= n)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

static void feed_make(const void *ctx, size_t first, size_t n, const uint32_t *index,
                      pfx_sprite *out) {
    const pfx_sprite_feed *f = ctx;
    if (index) {
        for (size_t k = 0; k < n; k++) {
            size_t i = pfx_sprite_feed_emitter(f, index[k]);
            out[k] = sprite_of(f->sim, i, (uint32_t)(index[k] - f->start[i]));
        }
        return;
    }
    /* In order: emitter by emitter, no search past the first. */
    for (size_t k = 0, i = n ? pfx_sprite_feed_emitter(f, first) : 0; k < n; i++)
        for (size_t m = first + k; m < f->start[i + 1] && k < n; m++, k++)
            out[k] = sprite_of(f->sim, i, (uint32_t)(m - f->start[i]));
}

static void feed_centres(const void *ctx, size_t first, size_t n, float *xyz) {
    const pfx_sprite_feed *f = ctx;
    for (size_t k = 0, i = n ? pfx_sprite_feed_emitter(f, first) : 0; k < n; i++) {
        const pfx_pool *p = &f->sim->pools[i];
        for (size_t m = first + k; m < f->start[i + 1] && k < n; m++, k++) {
            const size_t j = m - f->start[i];
            xyz[3 * k] = p->px[j];
            xyz[3 * k + 1] = p->py[j];
            xyz[3 * k + 2] = p->pz[j];
        }
    }
}

pfx_sprite_source pfx_sprite_feed_source(pfx_sprite_feed *f, const pfx_sim *s) {
    const pfx_effect *e = s->effect;
    size_t n = 0;
    f->sim = s;
    for (size_t i = 0; i < e->emitter_count; i++) {
        f->start[i] = n;
        if (e->emitters[i].look.draw == PFX_DRAW_SPRITE)
            n += s->pools[i].count;
    }
    f->start[e->emitter_count] = n;
    return (pfx_sprite_source){n, feed_make, feed_centres, f};
}
