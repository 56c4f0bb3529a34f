/* The steps of jobs/delivery.h. The manifest is written last, after every
 * output is in place and the stale ones are gone: a run that fails leaves
 * the previous manifest as it was, which still names what pfx wrote, so the
 * next run can clean up, and its hashes no longer match, so it cannot be
 * mistaken for up to date. */
#include "jobs/delivery.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>

#include "jobs/depfile.h"

bool pfx_delivery_begin(pfx_delivery *dl, const char *command, pfx_diags *d) {
    dl->now = pfx_manifest_create(command);
    if (!dl->now) {
        pfx_diag_error(d, PFX_RULE_OUT_OF_MEMORY, "out of memory");
        return false;
    }
    dl->prev = dl->manifest_path ? pfx_manifest_read(dl->manifest_path) : NULL;
    return true;
}

bool pfx_delivery_up_to_date(pfx_delivery *dl) {
    return !dl->force && dl->prev &&
           pfx_manifest_up_to_date(dl->prev, pfx_manifest_key(dl->now), dl->dir);
}

static void touch(const char *path) {
    if (path)
        utimensat(AT_FDCWD, path, NULL, 0);
}

bool pfx_delivery_skip(pfx_delivery *dl, pfx_diags *d) {
    touch(dl->manifest_path);
    touch(dl->target);
    return !dl->depfile || pfx_depfile_write(dl->depfile, dl->target, dl->now, d);
}

bool pfx_delivery_finish(pfx_delivery *dl, pfx_diags *d) {
    pfx_manifest_key(dl->now);
    if (dl->prev)
        dl->stale_removed = pfx_manifest_remove_stale(dl->prev, dl->now, dl->dir, d);
    if (dl->manifest_path && !pfx_manifest_write(dl->now, dl->manifest_path, d))
        return false;
    return !dl->depfile || pfx_depfile_write(dl->depfile, dl->target, dl->now, d);
}

void pfx_delivery_free(pfx_delivery *dl) {
    pfx_manifest_destroy(dl->now);
    pfx_manifest_destroy(dl->prev);
    dl->now = dl->prev = NULL;
}
