/* The file identities of jobs/input_files.h. */
#include "jobs/input_files.h"

#include <stdlib.h>
#include <sys/stat.h>

bool pfx_input_files_of(const pfx_manifest *m, pfx_input_files *files) {
    size_t n_in = m ? pfx_manifest_input_count(m) : 0;
    *files = (pfx_input_files){0};
    if (n_in == 0)
        return true;
    files->items = malloc(n_in * sizeof *files->items);
    if (!files->items)
        return false;
    for (size_t i = 0; i < n_in; i++) {
        struct stat st;
        const char *p = pfx_manifest_input(m, i);
        if (p && stat(p, &st) == 0)
            files->items[files->count++] = (pfx_input_file){st.st_dev, st.st_ino, p};
    }
    return true;
}

const char *pfx_input_files_match(const pfx_input_files *files, dev_t dev, ino_t ino) {
    for (size_t i = 0; i < files->count; i++)
        if (files->items[i].dev == dev && files->items[i].ino == ino)
            return files->items[i].path;
    return NULL;
}

const char *pfx_input_files_find(const pfx_input_files *files, const char *path) {
    struct stat st;
    if (files->count == 0 || stat(path, &st) != 0)
        return NULL;
    return pfx_input_files_match(files, st.st_dev, st.st_ino);
}

void pfx_input_files_free(pfx_input_files *files) {
    free(files->items);
    *files = (pfx_input_files){0};
}
