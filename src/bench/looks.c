/* The cost of each way a sprite can look, next to the plain round sprite
 * in the same run: one fixed field of sprites drawn with one material at a
 * time. A frame's time includes clearing, reading back and converting the
 * pixels the sprites cover (a few milliseconds at 512x512), the same for
 * every look, so the ratios slightly understate the differences. */
#include "bench/looks.h"

#include <math.h>
#include <stdlib.h>
#include <time.h>

#include "base/rng.h"
#include "render/shadow.h"

enum { SPRITES = 5000, FRAMES = 8, TEXTURE = 64, SHEET = 256 };

typedef struct look_case {
    const char *name;
    pfx_material material;
    int blur_samples; /* 0: no motion blur */
    bool ribbons;     /* the field as ribbon strips instead of sprites */
} look_case;

/* The field as ribbons: a strip of STRIP points from every STRIP-th
 * sprite, a wave 0.5 m long (about 130 px) as wide as the sprites, tapered
 * at both ends as taper: [0.2, 0.2] makes them, u along it (the triangles
 * render/ribbons_from_sim.c makes, made here without a simulation).
 * Writes 6 vertices a segment into v and returns how many. */
enum { STRIP = 50 };
static size_t make_ribbons(const pfx_sprite *s, size_t n, pfx_ribbon_vertex *v) {
    size_t m = 0;
    for (size_t first = 0; first + STRIP <= n; first += STRIP) {
        pfx_ribbon_vertex last[2] = {{0}};
        for (size_t k = 0; k < STRIP; k++) {
            const pfx_sprite *p = &s[first + k], *o = &s[first];
            const float along = (float)k / (STRIP - 1);
            const float x = o->x + 0.01f * (float)k, y = o->y + 0.05f * sinf(0.2f * (float)k);
            const float w = fminf(1.0f, fminf(along, 1 - along) / 0.2f), half = 0.5f * p->size * w;
            pfx_ribbon_vertex c[2];
            for (int e = 0; e < 2; e++)
                c[e] = (pfx_ribbon_vertex){.x = x,
                                           .y = y + (e ? -half : half),
                                           .z = o->z,
                                           .across = e ? -1.0f : 1.0f,
                                           .r = p->r * w,
                                           .g = p->g * w,
                                           .b = p->b * w,
                                           .along = along};
            if (k > 0) {
                v[m++] = last[0], v[m++] = last[1], v[m++] = c[0];
                v[m++] = last[1], v[m++] = c[1], v[m++] = c[0];
            }
            last[0] = c[0], last[1] = c[1];
        }
    }
    return m;
}

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* A field of additive sprites about 15 px wide over the middle of a
 * 512 px image under an orthographic camera 2 m high, each moving (for
 * stretch and blur) and at its own flipbook cell. */
static void make_sprites(pfx_sprite *s, size_t n) {
    pfx_rng rng;
    pfx_rng_seed(&rng, 0x5eed, 0);
    for (size_t i = 0; i < n; i++) {
        float u[8];
        for (int k = 0; k < 8; k++)
            u[k] = (float)pfx_rng_unit(&rng);
        float vx = 4 * u[4] - 2, vy = 4 * u[5] - 2;
        s[i] = (pfx_sprite){.x = 1.6f * u[0] - 0.8f,
                            .y = 1.6f * u[1] - 0.8f,
                            .size = 0.04f + 0.04f * u[2],
                            .r = 0.02f * u[3],
                            .g = 0.015f,
                            .b = 0.01f,
                            .angle = 6.2831853f * u[6],
                            .frame = 15.0f * u[7],
                            .variant = u[3],
                            .vx = vx,
                            .vy = vy,
                            .length = 0.04f + 0.04f * u[2]};
    }
}

/* A soft white disc in alpha, premultiplied, `cells` x `cells` times. */
static pfx_image make_texture(int side, int cells) {
    uint8_t *px = malloc((size_t)side * side * 4);
    int cell = side / cells;
    for (int y = 0; px && y < side; y++)
        for (int x = 0; x < side; x++) {
            double dx = ((x % cell) + 0.5) / cell * 2 - 1, dy = ((y % cell) + 0.5) / cell * 2 - 1;
            double f = 1 - (dx * dx + dy * dy);
            uint8_t a = (uint8_t)lround(255 * (f > 0 ? f * f : 0));
            uint8_t *p = px + ((size_t)y * side + x) * 4;
            p[0] = p[1] = p[2] = p[3] = a;
        }
    return (pfx_image){.path = "bench", .width = side, .height = side, .bits = 8, .pixels = px};
}

/* The self-shadowed row's opacity shadow map of the field, each sprite a
 * caster of alpha 0.5 under a light along -y, as the sprite builder makes
 * one a frame (render/shadow.h). */
static bool shade(pfx_renderer *r, pfx_shadow_volume *v, const pfx_sprite *s, size_t n,
                  pfx_diags *d) {
    pfx_shadow_begin(v, (const double[3]){0, -1, 0});
    for (size_t i = 0; i < n; i++)
        pfx_shadow_bound(v, (const float[3]){s[i].x, s[i].y, s[i].z}, 0.5f * s[i].size);
    pfx_shadow_frame(v);
    for (size_t i = 0; i < n; i++)
        pfx_shadow_splat(v, (const float[3]){s[i].x, s[i].y, s[i].z}, 0.5f * s[i].size, 0.5f);
    pfx_shadow_finish(v);
    return pfx_renderer_set_shadow(r, v, d);
}

/* Seconds per frame of the sprites drawn with material m (a shadowed one
 * building and uploading its shadow map every frame, in the time). */
static double frame_seconds(pfx_renderer *r, const pfx_camera *cam, const pfx_material *m, int blur,
                            pfx_sprite *s, size_t n, uint8_t *rgba, pfx_shadow_volume *shadow,
                            pfx_ribbons ribbons, pfx_diags *d) {
    if (!pfx_renderer_set_materials(r, m, 1, d))
        return -1;
    const float clear[4] = {0, 0, 0, 0};
    pfx_render_settings set = pfx_render_settings_plain(clear);
    set.light_dir[1] = -1;
    set.light_color[0] = set.light_color[1] = set.light_color[2] = 1;
    const pfx_sprite_source src = pfx_sprite_source_array(s, n);
    double t0 = now();
    for (int f = 0; f < FRAMES; f++) {
        bool ok = !m->shadowed || shade(r, shadow, s, n, d);
        if (ok && blur > 0) {
            ok = pfx_renderer_blur_begin(r, d);
            for (int k = 0; ok && k < blur; k++)
                ok = pfx_renderer_blur_add(r, cam, &set, &src, false, (pfx_ribbons){NULL, 0},
                                           1.0f / blur, d);
            if (ok)
                pfx_renderer_blur_resolve(r, &set, rgba);
        } else if (ok && ribbons.count) {
            ok = pfx_renderer_draw_frame(r, cam, &set, NULL, 0, false, ribbons, rgba, d);
        } else if (ok) {
            ok =
                pfx_renderer_draw_frame(r, cam, &set, s, n, false, (pfx_ribbons){NULL, 0}, rgba, d);
        }
        if (!ok)
            return -1;
    }
    return (now() - t0) / FRAMES;
}

bool pfx_bench_looks(FILE *out, pfx_renderer *r, int width, int height, pfx_diags *d) {
    pfx_image tex = make_texture(TEXTURE, 1), sheet = make_texture(SHEET, 4);
    pfx_sprite *s = malloc(SPRITES * sizeof *s);
    uint8_t *rgba = malloc((size_t)width * height * 4);
    pfx_shadow_volume *shadow = malloc(sizeof *shadow);
    pfx_ribbon_vertex *strips = malloc(6 * SPRITES * sizeof *strips);
    bool ok = tex.pixels && sheet.pixels && s && rgba && shadow && strips;
    if (!ok)
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory for the sprite benchmark");
    const pfx_material round = {.sprite = PFX_SPRITE_ROUND, .cols = 1, .rows = 1, .frames = 1};
    look_case cases[] = {
        {"round (the plain sprite)", round, 0, false},
        {"square", round, 0, false},
        {"spark", round, 0, false},
        {"smoke (noise puff)", round, 0, false},
        {"flare", round, 0, false},
        {"ring", round, 0, false},
        {"texture 64x64", round, 0, false},
        {"flipbook 4x4, cross-fade", round, 0, false},
        {"stretched along velocity", round, 0, false},
        {"lit (spherical normal)", round, 0, false},
        {"lit, self-shadowed (shadow map)", round, 0, false},
        {"ribbons, tapered (a point each)", round, 0, true},
        {"ribbons, tapered, textured", round, 0, true},
        {"motion blur, 2 samples", round, 2, false},
        {"motion blur, 4 samples", round, 4, false},
        {"motion blur, 8 samples", round, 8, false},
    };
    const size_t count = sizeof cases / sizeof *cases;
    cases[1].material.sprite = PFX_SPRITE_SQUARE;
    cases[2].material.sprite = PFX_SPRITE_SPARK;
    cases[3].material.sprite = PFX_SPRITE_SMOKE;
    cases[4].material.sprite = PFX_SPRITE_FLARE;
    cases[5].material.sprite = PFX_SPRITE_RING;
    cases[6].material.texture = &tex;
    cases[7].material.texture = &sheet;
    cases[7].material.cols = cases[7].material.rows = 4;
    cases[7].material.frames = 16;
    cases[7].material.frame_blend = true;
    cases[8].material.align = PFX_ALIGN_VELOCITY;
    cases[9].material.lit = true;
    cases[10].material.lit = cases[10].material.shadowed = true;
    cases[12].material.texture = &tex;
    pfx_camera cam = {.position = {0, 0, 5}, .up = {0, 1, 0}, .ortho = true, .ortho_height = 2};
    pfx_ribbons ribbons = {strips, 0};
    if (ok) {
        make_sprites(s, SPRITES);
        ribbons.count = make_ribbons(s, SPRITES, strips);
    }
    if (ok)
        fprintf(out,
                "sprites: %d additive sprites of 12-25 px at %dx%d through %s, one material at "
                "a time\n  %-34s %10s %10s %8s\n",
                SPRITES, width, height, pfx_renderer_name(r), "look", "ms/frame", "ns/sprite",
                "vs round");
    double base = 0;
    for (size_t k = 0; ok && k < count; k++) {
        double t =
            frame_seconds(r, &cam, &cases[k].material, cases[k].blur_samples, s, SPRITES, rgba,
                          shadow, cases[k].ribbons ? ribbons : (pfx_ribbons){NULL, 0}, d);
        ok = t > 0;
        double per = t / SPRITES;
        if (k == 0)
            base = per;
        if (ok)
            fprintf(out, "  %-34s %10.2f %10.1f %7.2fx\n", cases[k].name, 1e3 * t, 1e9 * per,
                    base > 0 ? per / base : 0);
    }
    free(tex.pixels);
    free(sheet.pixels);
    free(s);
    free(rgba);
    free(shadow);
    free(strips);
    return ok;
}
