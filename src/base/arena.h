/* A bump allocator: many small allocations, one free. The parsed document
 * and the compiled effect each live in one arena, so their lifetime is one
 * create and one destroy. */
#ifndef PFX_ARENA_H
#define PFX_ARENA_H

#include <stddef.h>

typedef struct pfx_arena_block pfx_arena_block;
typedef struct pfx_arena {
    pfx_arena_block *head;
    size_t used_total; /* bytes handed out, for `pfx info` */
} pfx_arena;

/* Returns zeroed memory aligned for any type, or NULL when out of memory. The
 * memory lives until pfx_arena_free. */
void *pfx_arena_alloc(pfx_arena *a, size_t size);
/* Copies n bytes of s and a terminating NUL into the arena. */
char *pfx_arena_strndup(pfx_arena *a, const char *s, size_t n);
void pfx_arena_free(pfx_arena *a);

#endif
