/* pfx assemble: the frames of a render run as slices (--slice, possibly on
 * many machines) gathered into one directory with one manifest, checked
 * frame by frame against the slices' manifests. */
#ifndef PFX_JOBS_ASSEMBLE_H
#define PFX_JOBS_ASSEMBLE_H

#include <stdbool.h>
#include <stddef.h>

#include "base/diag.h"
#include "output/atlas.h"

typedef struct pfx_assemble_report {
    size_t effects;        /* renders assembled (one manifest each) */
    size_t frames;         /* frames in the result */
    size_t linked, copied; /* hard links made, files copied (another file system) */
    size_t kept;           /* already in place with the right hash */
} pfx_assemble_report;

/* Finds every slice manifest (<name>.slice-I-of-N.manifest.json) in the
 * n directories, and for each render among them checks that every slice is
 * there exactly once and every frame has its recorded SHA-256, then gathers
 * the frames (and --motion-vectors' frames) into out (hard links where
 * possible) and writes out/<name>.manifest.json, the manifest a
 * single-process render would have written, with the atlas, the
 * motion-vector sidecar or sheet and the preview of opt as render would
 * make them from all the frames. out must exist. False with the reasons in d; a render whose
 * slices do not check out gets no manifest. */
typedef struct pfx_assemble_options {
    const pfx_atlas_layout *atlas; /* build <name>_atlas.png/.json in out, or NULL */
    const char *preview;           /* write this animated WebP (one render only), or NULL */
    int preview_quality;           /* --preview-quality, or -1 */
} pfx_assemble_options;

bool pfx_assemble(const char *const *dirs, size_t n, const char *out,
                  const pfx_assemble_options *opt, pfx_assemble_report *r, pfx_diags *d);

#endif
