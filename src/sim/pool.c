/* Particle pools as columns: layout and allocation, swap-remove, copies
 * between pools, offset views and the state hash, each one loop over the
 * column list of sim/columns.h. Nothing here knows what a column means. */
#include "sim/pool.h"

#include <math.h>
#include <string.h>

#include "base/hash.h"
#include "sim/columns.h"

#define STATE 1
#define SCRATCH 0
#define CARRY 2

/* Bytes per particle of one element type, for the alignment classes. */
#define COLUMN_BYTES(type) sizeof(type)

/* Bytes per particle of the columns em keeps, or of its SCRATCH ones. */
static size_t kept_bytes(const pfx_emitter *em, bool scratch_only) {
    size_t bytes = 0;
#define ADD_BYTES(name, type, role, needed, what)                                                  \
    if ((!scratch_only || role == SCRATCH) && (needed))                                            \
        bytes += sizeof(type);
    PFX_POOL_COLUMNS(ADD_BYTES)
#undef ADD_BYTES
    return bytes;
}

size_t pfx_pool_bytes_per_particle(const pfx_emitter *em) { return kept_bytes(em, false); }

size_t pfx_pool_scratch_bytes_per_particle(const pfx_emitter *em) { return kept_bytes(em, true); }

/* Bytes of a pool of n particles, rounded up to 8 so the next pool's
 * 8-byte columns stay aligned. */
size_t pfx_pool_bytes(const pfx_emitter *em, uint32_t n) {
    size_t b = pfx_pool_bytes_per_particle(em) * n;
    return (b + 7) & ~(size_t)7;
}

/* Columns are laid out largest element first (8, then 4, then 1 byte), so
 * every column is aligned within a block that starts 8-byte aligned. */
void pfx_pool_layout(pfx_pool *p, const pfx_emitter *em, void *block, uint32_t n) {
    unsigned char *next = block;
    for (size_t width = 8; width >= 1; width /= 2) {
#define PLACE(name, type, role, needed, what)                                                      \
    if (sizeof(type) == width) {                                                                   \
        p->name = NULL;                                                                            \
        if (needed) {                                                                              \
            p->name = (type *)(void *)next;                                                        \
            next += sizeof(type) * (size_t)n;                                                      \
        }                                                                                          \
    }
        PFX_POOL_COLUMNS(PLACE)
#undef PLACE
    }
    p->capacity = n;
    p->count = 0;
    p->newborn = 0;
    p->time = 0;
    p->may_run_away = false;
    p->death_floor = INFINITY;
}

void pfx_pool_move(pfx_pool *p, uint32_t to, uint32_t from) {
#define MOVE(name, type, role, needed, what)                                                       \
    if (role != SCRATCH && p->name)                                                                \
        memcpy(&p->name[to], &p->name[from], sizeof(type));
    PFX_POOL_COLUMNS(MOVE)
#undef MOVE
}

void pfx_pool_copy(pfx_pool *dst, const pfx_pool *src) {
#define COPY(name, type, role, needed, what)                                                       \
    if (role != SCRATCH && src->name)                                                              \
        memcpy(dst->name, src->name, sizeof(type) * (size_t)src->count);
    PFX_POOL_COLUMNS(COPY)
#undef COPY
    dst->count = src->count;
    dst->time = src->time;
    dst->may_run_away = src->may_run_away;
    dst->death_floor = src->death_floor;
}

pfx_pool pfx_pool_from(const pfx_pool *p, uint32_t from) {
    pfx_pool v = *p;
#define OFFSET(name, type, role, needed, what)                                                     \
    if (v.name)                                                                                    \
        v.name += from;
    PFX_POOL_COLUMNS(OFFSET)
#undef OFFSET
    v.count -= from;
    v.capacity -= from;
    return v;
}

uint64_t pfx_pool_hash(const pfx_pool *p, uint64_t h) {
#define HASH(name, type, role, needed, what)                                                       \
    if (role == STATE && p->name)                                                                  \
        h = pfx_fnv1a(h, p->name, sizeof(type) * (size_t)p->count);
    PFX_POOL_COLUMNS(HASH)
#undef HASH
    return pfx_fnv1a_u32(h, p->count);
}
