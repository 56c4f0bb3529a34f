/* Simulation state -> ribbons: the points a trail laid for one parent,
 * joined in birth order into a strip of triangles that faces the camera,
 * and on to the parent itself while it lives. Each point gives the strip
 * its width (size), colour and alpha over life; the renderer only projects
 * the result. It neither simulates nor draws. */
#include "render/sprites.h"

#include <math.h>
#include <stdlib.h>

/* A live point: its strip (the parent's id) and its place in it (its
 * birth time; its id breaks ties). A child's id is a hash of its event
 * (sim/spawn.h), not a count, so birth order is the time itself. */
typedef struct point_key {
    uint64_t key; /* parent_id << 32 | id: unique within an emitter */
    double birth; /* s; 0 for the parents' keys */
    uint32_t j;   /* its row in the pool */
} point_key;

/* One point of a strip, as the triangles need it. */
typedef struct strip_point {
    double p[3];
    double half;     /* half-width, m (widened to the minimum footprint by widen) */
    float rgba[4];   /* premultiplied, as a sprite's */
    double px_per_m; /* pixels a metre at its depth, for the widening */
    double along;    /* the fraction of the strip's length from its head (0) to its tail (1) */
} strip_point;

struct pfx_ribbon_buffer {
    pfx_ribbon_vertex *v; /* 6 per point: two triangles per segment */
    point_key *keys;
    point_key *parents; /* the feeding pool's live particles by id */
    strip_point *points;
    size_t largest; /* the largest ribbon pool */
};

pfx_ribbon_buffer *pfx_ribbons_create(const pfx_effect *e) {
    pfx_ribbon_buffer *b = calloc(1, sizeof *b);
    if (!b)
        return NULL;
    size_t total = 0, parents = 0;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        if (em->look.draw != PFX_DRAW_RIBBON)
            continue;
        total += em->capacity;
        b->largest = em->capacity > b->largest ? em->capacity : b->largest;
        uint32_t cap = e->emitters[em->ribbon_parent].capacity;
        parents = cap > parents ? cap : parents;
    }
    /* A strip of m points and its parent has m segments: 6 vertices a point. */
    b->v = malloc((6 * total + 1) * sizeof *b->v);
    b->keys = malloc((b->largest + 1) * sizeof *b->keys);
    b->parents = malloc((parents + 1) * sizeof *b->parents);
    b->points = malloc((b->largest + 1) * sizeof *b->points);
    if (!b->v || !b->keys || !b->parents || !b->points) {
        pfx_ribbons_destroy(b);
        return NULL;
    }
    return b;
}

void pfx_ribbons_destroy(pfx_ribbon_buffer *b) {
    if (!b)
        return;
    free(b->v);
    free(b->keys);
    free(b->parents);
    free(b->points);
    free(b);
}

static int by_key(const void *a, const void *b) {
    uint64_t x = ((const point_key *)a)->key, y = ((const point_key *)b)->key;
    return (x > y) - (x < y);
}

/* Strip by strip (the parent's id), then by birth time, then by id. */
static int by_strip(const void *a, const void *b) {
    const point_key *p = a, *q = b;
    uint64_t x = p->key >> 32, y = q->key >> 32;
    if (x != y)
        return (x > y) - (x < y);
    if (p->birth != q->birth)
        return p->birth < q->birth ? -1 : 1;
    return by_key(a, b);
}

static void sub3(const double a[3], const double b[3], double out[3]) {
    for (int k = 0; k < 3; k++)
        out[k] = a[k] - b[k];
}

static void cross3(const double a[3], const double b[3], double out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot3(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The camera as the strips need it: eye, forward, its side vector, and the
 * pixels per metre at unit depth (perspective) or at any depth (ortho). */
typedef struct eye_frame {
    double eye[3], forward[3], side[3];
    double px_per_m;
    bool ortho;
} eye_frame;

static void eye_of(const pfx_effect *e, eye_frame *f) {
    double up[3];
    pfx_camera_frame(&e->camera, f->side, up, f->forward); /* checked at compile */
    for (int k = 0; k < 3; k++)
        f->eye[k] = e->camera.position[k];
    f->ortho = e->camera.ortho;
    f->px_per_m =
        f->ortho ? e->height / e->camera.ortho_height : e->height / (2 * tan(0.5 * e->camera.fov));
}

/* A strip's corners: at point k the side is cross(tangent, line of sight),
 * the tangent the chord from point k - 1 to k + 1 (one segment at the
 * ends), so neighbouring segments share their corners exactly and the
 * strip has no gaps. Where the side is undefined (a repeated point, or a
 * tangent along the line of sight) the previous side is kept, and a side
 * is turned to agree with the previous one, so the strip never twists. */
static size_t emit_strip(const eye_frame *f, const strip_point *pt, size_t m, float profile,
                         float material, pfx_ribbon_vertex *out) {
    size_t n = 0;
    double prev[3] = {f->side[0], f->side[1], f->side[2]};
    pfx_ribbon_vertex last[2];
    for (size_t k = 0; k < m; k++) {
        double t[3], sight[3], side[3];
        sub3(pt[k + 1 < m ? k + 1 : k].p, pt[k ? k - 1 : 0].p, t);
        if (f->ortho)
            for (int a = 0; a < 3; a++)
                sight[a] = f->forward[a];
        else
            sub3(pt[k].p, f->eye, sight);
        cross3(t, sight, side);
        double len = sqrt(dot3(side, side));
        if (len > 1e-12 * sqrt(dot3(t, t)) * sqrt(dot3(sight, sight)) && len > 0) {
            double s = dot3(side, prev) < 0 ? -1 / len : 1 / len;
            for (int a = 0; a < 3; a++)
                prev[a] = side[a] * s;
        }
        pfx_ribbon_vertex c[2];
        for (int e = 0; e < 2; e++) {
            const double sign = e ? -1 : 1;
            c[e] = (pfx_ribbon_vertex){.x = (float)(pt[k].p[0] + sign * pt[k].half * prev[0]),
                                       .y = (float)(pt[k].p[1] + sign * pt[k].half * prev[1]),
                                       .z = (float)(pt[k].p[2] + sign * pt[k].half * prev[2]),
                                       .across = (float)sign,
                                       .r = pt[k].rgba[0],
                                       .g = pt[k].rgba[1],
                                       .b = pt[k].rgba[2],
                                       .a = pt[k].rgba[3],
                                       .profile = profile,
                                       .along = (float)pt[k].along,
                                       .material = material};
        }
        if (k > 0) {
            out[n++] = last[0], out[n++] = last[1], out[n++] = c[0];
            out[n++] = last[1], out[n++] = c[1], out[n++] = c[0];
        }
        last[0] = c[0], last[1] = c[1];
    }
    return n;
}

/* Emitter i's points as strip points: width from size, colour from its
 * colour, alpha and intensity over life, and the scale widen needs. */
static void point_of(const pfx_emitter *em, const pfx_pool *p, uint32_t j, const eye_frame *f,
                     strip_point *out) {
    float c[4];
    pfx_particle_color(em, p, j, c);
    const float u = (float)pfx_particle_age(p, j) / p->lifetime[j];
    const float a = c[3], glow = a * pfx_look_intensity(&em->look, u);
    out->p[0] = p->px[j], out->p[1] = p->py[j], out->p[2] = p->pz[j];
    out->half = 0.5 * pfx_particle_size(em, p, j);
    out->px_per_m = f->px_per_m;
    if (!f->ortho) {
        double d[3];
        sub3(out->p, f->eye, d);
        double depth = dot3(d, f->forward);
        out->px_per_m = depth > 1e-9 ? out->px_per_m / depth : 0;
    }
    out->rgba[0] = c[0] * glow;
    out->rgba[1] = c[1] * glow;
    out->rgba[2] = c[2] * glow;
    out->rgba[3] = em->blend == PFX_BLEND_ADD ? 0.0f : a;
}

/* Each point's `along`: its distance from the head (the last point)
 * along the points, over the strip's length (0 everywhere for a strip of
 * no length). */
static void measure(strip_point *pt, size_t m) {
    double from_tail = 0;
    for (size_t k = 0; k < m; k++) {
        if (k > 0) {
            double d[3];
            sub3(pt[k].p, pt[k - 1].p, d);
            from_tail += sqrt(dot3(d, d));
        }
        pt[k].along = from_tail; /* for now: from the tail */
    }
    for (size_t k = 0; k < m; k++)
        pt[k].along = from_tail > 0 ? (from_tail - pt[k].along) / from_tail : 0;
}

/* `ribbon: { taper: [head, tail] }`: width and alpha times
 * min(1, h / head, t / tail), h = along and t = 1 - along the fractions of
 * the strip's length from the head and from the tail; a fraction of 0
 * tapers nothing at that end. */
static void taper(const double frac[2], strip_point *pt, size_t m) {
    if ((frac[0] <= 0 && frac[1] <= 0) || m < 2)
        return;
    for (size_t k = 0; k < m; k++) {
        const double h = pt[k].along, t = 1 - h;
        double w = 1;
        if (frac[0] > 0 && h < frac[0] * w)
            w = h / frac[0];
        if (frac[1] > 0 && t < frac[1] * w)
            w = t / frac[1];
        w = w < 0 ? 0 : w;
        pt[k].half *= w;
        for (int c = 0; c < 4; c++)
            pt[k].rgba[c] = (float)(pt[k].rgba[c] * w);
    }
}

/* A point narrower than the minimum footprint on screen is widened to it
 * with its colour scaled down by the widening, as a sprite is. */
static void widen(strip_point *pt) {
    double px = 2 * pt->half * pt->px_per_m, grow = 1;
    if (px > 0 && px < PFX_MIN_FOOTPRINT_PX) {
        grow = PFX_MIN_FOOTPRINT_PX / px;
        pt->half *= grow;
    }
    for (int c = 0; c < 4; c++)
        pt->rgba[c] = (float)(pt->rgba[c] / grow);
}

/* The row of the live parent with this id in keys (sorted by id), or -1. */
static long find_parent(const point_key *keys, size_t n, uint32_t id) {
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (keys[mid].key < id)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < n && keys[lo].key == id ? (long)keys[lo].j : -1;
}

pfx_ribbons pfx_ribbons_build(pfx_ribbon_buffer *b, const pfx_sim *s) {
    const pfx_effect *e = s->effect;
    eye_frame f;
    eye_of(e, &f);
    size_t n = 0;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        const pfx_pool *p = &s->pools[i];
        if (em->look.draw != PFX_DRAW_RIBBON || !p->parent_id)
            continue;
        size_t m = 0;
        for (uint32_t j = 0; j < p->count; j++)
            if (p->parent_id[j] != UINT32_MAX)
                b->keys[m++] =
                    (point_key){((uint64_t)p->parent_id[j] << 32) | p->id[j], p->birth[j], j};
        qsort(b->keys, m, sizeof *b->keys, by_strip);
        const pfx_pool *pp = &s->pools[em->ribbon_parent];
        for (uint32_t j = 0; j < pp->count; j++)
            b->parents[j] = (point_key){pp->id[j], 0, j};
        qsort(b->parents, pp->count, sizeof *b->parents, by_key);
        const float profile = em->look.sprite == PFX_SPRITE_SQUARE ? 1.0f : 0.0f;
        for (size_t first = 0; first < m;) {
            size_t end = first + 1;
            while (end < m && b->keys[end].key >> 32 == b->keys[first].key >> 32)
                end++;
            size_t count = end - first;
            for (size_t k = first; k < end; k++)
                point_of(em, p, b->keys[k].j, &f, &b->points[k - first]);
            /* While the parent lives the strip runs on to it, as wide and
             * bright as its youngest point: no gap of up to 1 / rate s. */
            long head = find_parent(b->parents, pp->count, (uint32_t)(b->keys[first].key >> 32));
            if (head >= 0) {
                strip_point *last = &b->points[count - 1], *h = &b->points[count];
                *h = *last;
                h->p[0] = pp->px[head], h->p[1] = pp->py[head], h->p[2] = pp->pz[head];
                if (h->p[0] != last->p[0] || h->p[1] != last->p[1] || h->p[2] != last->p[2])
                    count++;
            }
            measure(b->points, count);
            taper(em->look.ribbon_taper, b->points, count);
            for (size_t k = 0; k < count; k++)
                widen(&b->points[k]);
            n += emit_strip(&f, b->points, count, profile, (float)i, b->v + n);
            first = end;
        }
    }
    return (pfx_ribbons){b->v, n};
}

/* The sizes pfx_ribbons_create asks for: points (the ribbon pools), the
 * largest ribbon pool, the largest feeding pool. */
static void ribbon_sizes(const pfx_effect *e, size_t *total, size_t *largest, size_t *parents) {
    *total = *largest = *parents = 0;
    for (size_t i = 0; i < e->emitter_count; i++) {
        const pfx_emitter *em = &e->emitters[i];
        if (em->look.draw != PFX_DRAW_RIBBON)
            continue;
        *total += em->capacity;
        *largest = em->capacity > *largest ? em->capacity : *largest;
        size_t cap = e->emitters[em->ribbon_parent].capacity;
        *parents = cap > *parents ? cap : *parents;
    }
}

size_t pfx_ribbons_bytes(const pfx_effect *e) {
    size_t total, largest, parents;
    ribbon_sizes(e, &total, &largest, &parents);
    if (total == 0)
        return 0; /* a few bytes of empty buffers */
    /* The vertices twice: the array and the GL buffer they are uploaded to. */
    return 2 * (6 * total + 1) * sizeof(pfx_ribbon_vertex) + (largest + 1) * sizeof(point_key) +
           (parents + 1) * sizeof(point_key) + (largest + 1) * sizeof(strip_point);
}

size_t pfx_ribbons_triangles(const pfx_effect *e) {
    size_t total, largest, parents;
    ribbon_sizes(e, &total, &largest, &parents);
    return 2 * total;
}
