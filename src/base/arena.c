/* The bump allocator behind pfx_arena: blocks of at least 64 KiB chained in a
 * list; an allocation never moves, and everything is freed together. */
#include "base/arena.h"

#include <stdalign.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

struct pfx_arena_block {
    pfx_arena_block *next;
    size_t size, used;
    alignas(max_align_t) unsigned char data[];
};

void *pfx_arena_alloc(pfx_arena *a, size_t size) {
    const size_t align = alignof(max_align_t);
    size = (size + align - 1) & ~(align - 1);
    if (size == 0)
        size = align;
    pfx_arena_block *b = a->head;
    if (!b || b->size - b->used < size) {
        size_t block = size > 65536 ? size : 65536;
        b = malloc(sizeof *b + block);
        if (!b)
            return NULL;
        b->size = block;
        b->used = 0;
        b->next = a->head;
        a->head = b;
    }
    void *p = b->data + b->used;
    b->used += size;
    a->used_total += size;
    memset(p, 0, size);
    return p;
}

char *pfx_arena_strndup(pfx_arena *a, const char *s, size_t n) {
    char *p = pfx_arena_alloc(a, n + 1);
    if (p) {
        memcpy(p, s, n);
        p[n] = 0;
    }
    return p;
}

void pfx_arena_free(pfx_arena *a) {
    pfx_arena_block *b = a->head;
    while (b) {
        pfx_arena_block *next = b->next;
        free(b);
        b = next;
    }
    a->head = NULL;
    a->used_total = 0;
}
