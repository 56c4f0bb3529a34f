/* The bake's CSV rows (bake.c decides where they go and in what order):
 * floats with 9 significant digits, enough to round-trip a float; emitter
 * names quoted as RFC 4180 asks when they hold a comma, quote or break. */
#include <string.h>

#include "output/bake.h"
#include "output/bake_rows.h"

bool pfx_bake_csv_header(FILE *out) { return fputs(PFX_BAKE_HEADER "\n", out) >= 0; }

bool pfx_bake_csv_row(FILE *out, const pfx_bake_row *r) {
    char name[512];
    if (strpbrk(r->emitter_name, ",\"\r\n")) {
        size_t o = 0;
        name[o++] = '"';
        for (const char *c = r->emitter_name; *c && o < sizeof name - 3; c++) {
            if (*c == '"')
                name[o++] = '"';
            name[o++] = *c;
        }
        name[o++] = '"';
        name[o] = 0;
    } else {
        snprintf(name, sizeof name, "%s", r->emitter_name);
    }
    return fprintf(out,
                   "%ld,%.9g,%s,%u,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,"
                   "%.9g\n",
                   r->frame, r->time, name, r->id, r->pos[0], r->pos[1], r->pos[2], r->vel[0],
                   r->vel[1], r->vel[2], r->age, r->lifetime, r->size, r->color[0], r->color[1],
                   r->color[2], r->color[3]) > 0;
}
