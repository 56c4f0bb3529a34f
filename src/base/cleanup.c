/* The table of base/cleanup.h. A slot goes FREE -> FILLING (a writer
 * claimed it) -> READY (the path is complete) -> FREE; the handler only
 * reads READY slots, so it never sees half a path. */
#include "base/cleanup.h"

#include <stdatomic.h>
#include <string.h>
#include <unistd.h>

enum { SLOTS = 64, PATH_MAX_BYTES = 4352 };
enum { FREE, FILLING, READY };

static _Atomic int state[SLOTS];
static char paths[SLOTS][PATH_MAX_BYTES];

int pfx_cleanup_watch(const char *path) {
    size_t n = strlen(path);
    if (n >= PATH_MAX_BYTES)
        return -1;
    for (int i = 0; i < SLOTS; i++) {
        int expected = FREE;
        if (atomic_compare_exchange_strong(&state[i], &expected, FILLING)) {
            memcpy(paths[i], path, n + 1);
            atomic_store(&state[i], READY);
            return i;
        }
    }
    return -1;
}

void pfx_cleanup_forget(int slot) {
    if (slot >= 0 && slot < SLOTS)
        atomic_store(&state[slot], FREE);
}

void pfx_cleanup_now(void) {
    for (int i = 0; i < SLOTS; i++)
        if (atomic_load(&state[i]) == READY)
            unlink(paths[i]);
}
