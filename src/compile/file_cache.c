/* The files an effect names, read once each: a list (in the compile's
 * arena) of what each regular file gave, keyed by device and inode and
 * the kind of reading. Sixty-four emitters naming one 176 MB mesh read it
 * once, not 64 times into the arena before any memory check could run.
 * It reads no file itself: the texture and mesh readers look here first. */
#include <sys/stat.h>

#include "compile/read.h"

struct pfx_loaded_file {
    dev_t dev;
    ino_t ino;
    int kind;
    double param;
    const void *result;
    pfx_loaded_file *next;
};

/* The file's identity, or false when it is not a regular file (a FIFO, a
 * device, a missing file: the reader reports those, every time). */
static bool identify(const char *path, dev_t *dev, ino_t *ino) {
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
        return false;
    *dev = st.st_dev;
    *ino = st.st_ino;
    return true;
}

const void *pfx_file_cache_find(pfx_reader *r, const char *path, int kind, double param) {
    dev_t dev;
    ino_t ino;
    if (!identify(path, &dev, &ino))
        return NULL;
    for (const pfx_loaded_file *f = r->files; f; f = f->next)
        if (f->dev == dev && f->ino == ino && f->kind == kind && f->param == param)
            return f->result;
    return NULL;
}

void pfx_file_cache_add(pfx_reader *r, const char *path, int kind, double param,
                        const void *result) {
    dev_t dev;
    ino_t ino;
    pfx_loaded_file *f;
    if (!result || !identify(path, &dev, &ino) || !(f = pfx_arena_alloc(r->arena, sizeof *f)))
        return; /* not remembered: a later name reads it again */
    *f = (pfx_loaded_file){dev, ino, kind, param, result, r->files};
    r->files = f;
}
