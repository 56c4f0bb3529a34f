/* The depth sort of alpha-blended sprites: back to front by view depth,
 * stable and exactly reproducible. */
#include "render/render_internal.h"

#include <stdlib.h>
#include <string.h>

static bool grow_scratch(pfx_renderer *r, size_t count, pfx_diags *d) {
    if (count <= r->scratch_cap)
        return true;
    size_t cap = r->scratch_cap ? r->scratch_cap : 1024;
    while (cap < count)
        cap *= 2;
    uint32_t *keys = realloc(r->keys, 2 * cap * sizeof *keys);
    if (keys)
        r->keys = keys;
    uint32_t *index = realloc(r->index, 2 * cap * sizeof *index);
    if (index)
        r->index = index;
    pfx_sprite *sorted = realloc(r->sorted, cap * sizeof *sorted);
    if (sorted)
        r->sorted = sorted;
    if (!keys || !index || !sorted) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory sorting %zu sprites", count);
        return false;
    }
    r->scratch_cap = cap;
    return true;
}

/* Maps a float to a uint32 whose unsigned order is the float's order
 * (negative floats have all bits flipped, positive ones only the sign). */
static uint32_t float_order_key(float x) {
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    return (b & 0x80000000u) ? ~b : (b | 0x80000000u);
}

/* Back-to-front sort by view depth (distance along the camera's forward
 * axis), farthest first. LSD radix sort on 32-bit keys, 8 bits per pass:
 * O(n), stable by construction (equal depths keep input order), and exactly
 * reproducible. Keys are inverted so that ascending key = descending depth.
 * Passes where every key has the same digit are skipped. */
bool pfx_sort_back_to_front(pfx_renderer *r, const pfx_view *v, pfx_sprite *sprites, size_t count,
                            pfx_diags *d) {
    if (count < 2)
        return true;
    if (count > UINT32_MAX) {
        pfx_diag_error(d, PFX_RULE_TOO_MANY, "too many sprites to sort: %zu", count);
        return false;
    }
    if (!grow_scratch(r, count, d))
        return false;
    uint32_t *key = r->keys, *key_tmp = r->keys + r->scratch_cap;
    uint32_t *idx = r->index, *idx_tmp = r->index + r->scratch_cap;
    const double fx = v->forward[0], fy = v->forward[1], fz = v->forward[2];
    const double ex = v->eye[0], ey = v->eye[1], ez = v->eye[2];
    for (size_t i = 0; i < count; i++) {
        double depth =
            (sprites[i].x - ex) * fx + (sprites[i].y - ey) * fy + (sprites[i].z - ez) * fz;
        key[i] = ~float_order_key((float)depth);
        idx[i] = (uint32_t)i;
    }
    for (int shift = 0; shift < 32; shift += 8) {
        size_t hist[256] = {0};
        for (size_t i = 0; i < count; i++)
            hist[(key[i] >> shift) & 0xff]++;
        if (hist[(key[0] >> shift) & 0xff] == count)
            continue; /* all keys share this digit: the pass would not move anything */
        size_t sum = 0;
        for (int d = 0; d < 256; d++) {
            size_t c = hist[d];
            hist[d] = sum;
            sum += c;
        }
        for (size_t i = 0; i < count; i++) {
            size_t dst = hist[(key[i] >> shift) & 0xff]++;
            key_tmp[dst] = key[i];
            idx_tmp[dst] = idx[i];
        }
        uint32_t *t = key;
        key = key_tmp;
        key_tmp = t;
        t = idx;
        idx = idx_tmp;
        idx_tmp = t;
    }
    for (size_t i = 0; i < count; i++)
        r->sorted[i] = sprites[idx[i]];
    memcpy(sprites, r->sorted, count * sizeof *sprites);
    return true;
}
