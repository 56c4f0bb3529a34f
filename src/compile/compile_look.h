/* How particles are drawn (compile/compile_look.c): an emitter's sprite,
 * texture, flipbook, orientation, lighting and intensity; the effect's
 * light and motion blur. */
#ifndef PFX_COMPILE_LOOK_H
#define PFX_COMPILE_LOOK_H

#include "compile/keys.h"
#include "compile/read.h"

extern const pfx_key_table pfx_flipbook_table, pfx_stretch_table, pfx_ribbon_table, pfx_light_table,
    pfx_motion_blur_table;

/* The effect's look defaults: dither on, no motion blur (1 sample), the
 * default light (straight down, white, ambient 0.25). */
void pfx_look_defaults(pfx_effect *e);
/* `light:` and `image.motion_blur:` into e. */
void pfx_compile_light(pfx_reader *r, const pfx_node *v, pfx_effect *e);
/* After the emitters: warns at light.shadows when no emitter is lit (the
 * shadows would darken nothing). */
void pfx_check_shadows(pfx_reader *r, const pfx_node *root, const pfx_effect *e);
void pfx_compile_motion_blur(pfx_reader *r, const pfx_node *v, pfx_effect *e);
/* The look keys of emitter mapping n that its key table does not read
 * itself (texture, normal_map, the flipbook's checks, axis/normal,
 * intensity), after pfx_keys_read; textures are read relative to
 * effect_path. */
void pfx_compile_look(pfx_reader *r, const pfx_node *n, pfx_emitter *em, const char *effect_path);

#endif
