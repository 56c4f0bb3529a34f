/* Binary particle caches: PLY (binary_little_endian 1.0, one `vertex`
 * element) and Unity VFX Graph's point cache (`pcache`, format binary 1.0).
 * Both are a text header naming typed properties, then fixed-size
 * little-endian records; one table of columns gives both headers and the
 * record layout. Every baked frame is in the one file, told apart by the
 * `frame` property. */
#include <string.h>

#include "output/bake_rows.h"

typedef enum { COL_INT, COL_UINT, COL_FLOAT } col_type;

typedef struct column {
    col_type type;
    const char *ply, *pcache;
} column;

/* PLY names follow the common convention (x, y, z; red, green, blue,
 * alpha); pcache names are the VFX Graph attributes they fill. */
static const column columns[] = {
    {COL_INT, "frame", "frame"},     {COL_UINT, "emitter", "emitter"},
    {COL_UINT, "id", "id"},          {COL_FLOAT, "x", "position.x"},
    {COL_FLOAT, "y", "position.y"},  {COL_FLOAT, "z", "position.z"},
    {COL_FLOAT, "vx", "velocity.x"}, {COL_FLOAT, "vy", "velocity.y"},
    {COL_FLOAT, "vz", "velocity.z"}, {COL_FLOAT, "red", "color.r"},
    {COL_FLOAT, "green", "color.g"}, {COL_FLOAT, "blue", "color.b"},
    {COL_FLOAT, "alpha", "color.a"}, {COL_FLOAT, "size", "size"},
    {COL_FLOAT, "age", "age"},       {COL_FLOAT, "lifetime", "lifetime"},
};
enum { COLUMN_COUNT = sizeof columns / sizeof *columns };
_Static_assert(COLUMN_COUNT * 4 == PFX_BAKE_RECORD_BYTES, "one 4-byte field per column");

static void put_u32(unsigned char *p, uint32_t v) {
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

void pfx_bake_record(const pfx_bake_row *r, unsigned char rec[PFX_BAKE_RECORD_BYTES]) {
    /* The values in the order of `columns`. */
    const float f[] = {r->pos[0], r->pos[1],     r->pos[2],   r->vel[0],   r->vel[1],
                       r->vel[2], r->color[0],   r->color[1], r->color[2], r->color[3],
                       r->size,   (float)r->age, r->lifetime};
    put_u32(rec, (uint32_t)(int32_t)r->frame);
    put_u32(rec + 4, r->emitter);
    put_u32(rec + 8, r->id);
    for (size_t k = 0; k < sizeof f / sizeof *f; k++) {
        uint32_t bits;
        memcpy(&bits, &f[k], 4);
        put_u32(rec + 12 + 4 * k, bits);
    }
}

/* The effect's name and its emitters by index, as comment lines (a name
 * with a line break would end the comment: it is cut there). */
static void comments(FILE *out, const pfx_effect *e) {
    fprintf(out, "comment pfx bake of %.*s\n", (int)strcspn(e->path, "\r\n"), e->path);
    for (size_t i = 0; i < e->emitter_count; i++)
        fprintf(out, "comment emitter %zu %.*s\n", i, (int)strcspn(e->emitters[i].name, "\r\n"),
                e->emitters[i].name);
}

bool pfx_bake_ply_header(FILE *out, const pfx_effect *e, uint64_t count) {
    static const char *const types[] = {"int", "uint", "float"};
    fputs("ply\nformat binary_little_endian 1.0\n", out);
    comments(out, e);
    fprintf(out, "element vertex %llu\n", (unsigned long long)count);
    for (int k = 0; k < COLUMN_COUNT; k++)
        fprintf(out, "property %s %s\n", types[columns[k].type], columns[k].ply);
    return fputs("end_header\n", out) >= 0;
}

/* Unity's importer knows float, int and uchar: ids and emitters are ints. */
bool pfx_bake_pcache_header(FILE *out, const pfx_effect *e, uint64_t count) {
    fputs("pcache\nformat binary 1.0\n", out);
    comments(out, e);
    fprintf(out, "elements %llu\n", (unsigned long long)count);
    for (int k = 0; k < COLUMN_COUNT; k++)
        fprintf(out, "property %s %s\n", columns[k].type == COL_FLOAT ? "float" : "int",
                columns[k].pcache);
    return fputs("end_header\n", out) >= 0;
}
