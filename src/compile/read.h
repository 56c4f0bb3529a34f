/* Typed readers over parsed nodes, each reporting a located error on a wrong
 * type or malformed value: numbers, vectors, random values, colours and
 * gradients, and the unknown-key check with its did-you-mean suggestion. */
#ifndef PFX_READ_H
#define PFX_READ_H

#include "base/arena.h"
#include "base/diag.h"
#include "compile/colour_text.h"
#include "model/effect.h"
#include "parse/node.h"

typedef struct pfx_loaded_file pfx_loaded_file;
typedef struct pfx_reader {
    pfx_diags *d;
    pfx_arena *arena;
    pfx_loaded_file *files; /* what was read of the files named so far */
} pfx_reader;

/* Files an effect names (textures, meshes) are read once each, however
 * many keys name them (compile/file_cache.c). What a file gave for a kind
 * of reading (`kind`, with its parameter: a mesh's scale, whether a
 * texture is premultiplied) is found by the file's device and inode, so
 * that two names of one file (./a.png and a.png, a symbolic link) share
 * it; NULL when it was not read so before, or path is not a regular file. */
enum { PFX_FILE_TEXTURE, PFX_FILE_MESH };
const void *pfx_file_cache_find(pfx_reader *r, const char *path, int kind, double param);
/* Remembers result (in r's arena, living as long as it) for path. */
void pfx_file_cache_add(pfx_reader *r, const char *path, int kind, double param,
                        const void *result);

/* Where to blame a problem found while reading what node n names (the
 * file a key points to). */
pfx_diag_at pfx_read_at(pfx_reader *r, const pfx_node *n);
/* Reports an error (a warning) of kind `rule` at node n, underlining it. */
void pfx_read_error(pfx_reader *r, const pfx_node *n, pfx_rule rule, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
void pfx_read_warning(pfx_reader *r, const pfx_node *n, pfx_rule rule, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* Checks that every key of map is in the NULL-terminated list `allowed`;
 * reports the others, suggesting the nearest allowed key. `where` names the
 * mapping in messages ("emitter 'flame'"). Returns false if any was unknown. */
bool pfx_read_check_keys(pfx_reader *r, const pfx_node *map, const char *const *allowed,
                         const char *where);
/* The allowed name nearest to `word` by edit distance, or NULL if none is
 * close enough to be a likely misspelling. */
const char *pfx_suggest(const char *word, const char *const *allowed);

/* Requires n to be a mapping; reports and returns false otherwise. */
bool pfx_read_map(pfx_reader *r, const pfx_node *n, const char *what);

/* A finite number. `what` names the key in messages. */
bool pfx_read_number(pfx_reader *r, const pfx_node *n, const char *what, double *out);
/* A non-negative integer below 2^64. */
bool pfx_read_uint(pfx_reader *r, const pfx_node *n, const char *what, uint64_t *out);
/* A list of exactly `count` numbers. */
bool pfx_read_numbers(pfx_reader *r, const pfx_node *n, const char *what, double *out, int count);
/* An optional 3-vector `key` of map, each component within +-limit; out
 * keeps its default when the key is absent. */
bool pfx_read_vec3_within(pfx_reader *r, const pfx_node *map, const char *key, double out[3],
                          double limit);
/* A list of keys [{<time_key>: t, value: v}, ...]: times within [t_lo,
 * t_hi], increasing (strictly when `strict`), values of `dims` numbers each
 * (v_lo < v_hi: every number within them). Writes n->count times into t
 * and n->count * dims numbers into v (the caller sizes both to `max`). */
typedef struct pfx_key_list_spec {
    const char *what, *time_key;
    size_t max;
    int dims;
    bool strict;
    double t_lo, t_hi, v_lo, v_hi;
} pfx_key_list_spec;
bool pfx_read_key_list(pfx_reader *r, const pfx_node *n, const pfx_key_list_spec *spec, double *t,
                       double *v);
/* A random value: number, [min, max], {mean, var} or {normal: [m, sd], clamp: [lo, hi]}. */
bool pfx_read_value(pfx_reader *r, const pfx_node *n, const char *what, pfx_value *out);
/* A value whose every sample lies in [lo, hi] (above lo strictly when
 * lo_strict); a bound the user did not write (mean - var, a normal's
 * 3-sigma cut) is named as such. */
bool pfx_read_value_in(pfx_reader *r, const pfx_node *n, const char *what, pfx_value *v, double lo,
                       bool lo_strict, double hi);
/* A colour: "#rgb", "#rgba", "#rrggbb", "#rrggbbaa", a CSS colour name
 * (compile/css_colours.h), transparent, [r, g, b] or [r, g, b, a],
 * components in 0..rgb_max (above 1: an HDR colour, for light), alpha in
 * 0..1. */
#define PFX_HDR_MAX 1000.0
bool pfx_read_color(pfx_reader *r, const pfx_node *n, const char *what, double rgb_max,
                    float out[4]);
/* A colour or a gradient (a list of colours, evenly spaced, or of {at, color}
 * stops), sampled into the lookup table. */
bool pfx_read_gradient(pfx_reader *r, const pfx_node *n, const char *what, double rgb_max,
                       pfx_gradient *out);
/* One of the NULL-terminated `names`: its index, or -1 after reporting the
 * unknown word with a suggestion or the list of choices. */
int pfx_read_enum(pfx_reader *r, const pfx_node *n, const char *key, const char *what,
                  const char *const *names);
/* A plain string. */
bool pfx_read_string(pfx_reader *r, const pfx_node *n, const char *what, const char **out);
/* A file name (a string) as written, in *name, and its path in `path`:
 * relative to the directory of the effect file `effect_path` unless it is
 * absolute. False after reporting a non-string or a path over `size`. */
bool pfx_read_path(pfx_reader *r, const pfx_node *n, const char *what, const char *effect_path,
                   const char **name, char *path, size_t size);

/* Range checks: `got` (a number, or a value's smallest or largest sample)
 * must be above (below) `bound`, strictly when `strict`. Each reports at n:
 * "'rate' must be at least 0, got -3". */
bool pfx_check_above(pfx_reader *r, const pfx_node *n, const char *what, double got, double bound,
                     bool strict);
bool pfx_check_below(pfx_reader *r, const pfx_node *n, const char *what, double got, double bound,
                     bool strict);

#endif
