/* Loading a Wavefront OBJ surface for the `mesh` emitter shape: triangles
 * and their cumulative areas, ready for area-weighted sampling. */
#ifndef PFX_MESH_LOAD_H
#define PFX_MESH_LOAD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "base/arena.h"
#include "base/diag.h"

#define PFX_MESH_MAX_TRIANGLES 1000000u
#define PFX_MESH_MAX_VERTICES 3000000u
#define PFX_MESH_MAX_BYTES (256u << 20)

typedef struct pfx_mesh {
    const double *verts;  /* x, y, z per vertex */
    const uint32_t *tris; /* three 0-based vertex indices per triangle */
    const double *cum;    /* cum[i]: total area of triangles 0..i */
    uint32_t vert_count, tri_count;
} pfx_mesh;

/* Parses OBJ text: `v x y z [w]` and `f i i i ...` (i, i/t, i//n or i/t/n;
 * negative i counts back from the last vertex so far; polygons split into
 * a fan from their first vertex); every other statement is ignored. Every
 * coordinate is multiplied by `scale`. The arrays live in arena `a`. On a
 * malformed file, reports "'<name>' line 12: ..." at `at` (the key that
 * named the file) and returns false. */
bool pfx_mesh_parse(const char *text, size_t len, const char *name, double scale, pfx_arena *a,
                    pfx_mesh *m, const pfx_diag_at *at);

/* Reads file `path` and parses it as above; messages name the file `name`
 * (as the user wrote it): "cannot open 'x.obj': No such file or directory". */
bool pfx_mesh_load(const char *path, const char *name, double scale, pfx_arena *a, pfx_mesh *m,
                   const pfx_diag_at *at);

#endif
