/* The inputs of a run as files (device and inode), not as strings:
 * "a.png", "./a.png" and a link to it are the same file. Used wherever
 * pfx is about to write or remove a file, so that it never destroys one
 * the run reads (jobs/output_names.c before the work, the stale-output
 * removal of jobs/manifest.c after it). */
#ifndef PFX_JOBS_INPUT_FILES_H
#define PFX_JOBS_INPUT_FILES_H

#include <stdbool.h>
#include <stddef.h>
#include <sys/types.h>

#include "jobs/manifest.h"

typedef struct pfx_input_file {
    dev_t dev;
    ino_t ino;
    const char *path; /* borrowed from the manifest */
} pfx_input_file;

typedef struct pfx_input_files {
    pfx_input_file *items;
    size_t count;
} pfx_input_files;

/* Stats every input m lists (one that does not exist is left out: it
 * cannot be overwritten). m may be NULL (no inputs). False when out of
 * memory; files is then empty. The paths stay m's. */
bool pfx_input_files_of(const pfx_manifest *m, pfx_input_files *files);
/* The input path names the same file as, or NULL (also when path does
 * not exist). */
const char *pfx_input_files_find(const pfx_input_files *files, const char *path);
/* The same for a file already stat'd: the input with that device and
 * inode, or NULL. */
const char *pfx_input_files_match(const pfx_input_files *files, dev_t dev, ino_t ino);
void pfx_input_files_free(pfx_input_files *files);

#endif
