/* The name lists of model/kinds.h, each expanded from its one table. */
#include "model/kinds.h"

#include <stdio.h>
#include <string.h>

#define NAME2(e, name) name,
#define NAME3(e, name, a) name,
#define NAME4(e, name, a, b) name,
#define THIRD4(e, name, a, b) a,
#define FOURTH4(e, name, a, b) b,

const char *const pfx_force_names[] = {PFX_FORCE_KINDS(NAME4) NULL};
const char *const pfx_force_words[] = {PFX_FORCE_KINDS(THIRD4) NULL};
const char *const pfx_force_docs[] = {PFX_FORCE_KINDS(FOURTH4) NULL};
const char *const pfx_integrator_names[] = {PFX_INTEGRATOR_KINDS(NAME4) NULL};
const char *const pfx_integrator_orders[] = {PFX_INTEGRATOR_KINDS(THIRD4) NULL};
const char *const pfx_shape_names[] = {PFX_SHAPE_KINDS(NAME2) NULL};
const char *const pfx_emit_from_names[] = {PFX_EMIT_FROM_KINDS(NAME2) NULL};
const char *const pfx_deflector_names[] = {PFX_DEFLECTOR_KINDS(NAME2) NULL};
const char *const pfx_deflect_response_names[] = {PFX_DEFLECT_RESPONSES(NAME2) NULL};
const char *const pfx_kill_names[] = {PFX_KILL_KINDS(NAME2) NULL};
const char *const pfx_kill_shape_names[] = {PFX_KILL_SHAPES(NAME2) NULL};
const char *const pfx_bounds_mode_names[] = {PFX_BOUNDS_MODES(NAME2) NULL};
const char *const pfx_spawn_event_names[] = {PFX_SPAWN_EVENTS(NAME2) NULL};
const char *const pfx_blend_names[] = {PFX_BLEND_KINDS(NAME2) NULL};
const char *const pfx_sprite_names[] = {PFX_SPRITE_KINDS(NAME2) NULL};
const char *const pfx_draw_names[] = {PFX_DRAW_KINDS(NAME2) NULL};
const char *const pfx_align_names[] = {PFX_ALIGN_KINDS(NAME2) NULL};
const char *const pfx_tonemap_names[] = {PFX_TONEMAP_KINDS(NAME2) NULL};
const char *const pfx_alpha_mode_names[] = {PFX_ALPHA_MODES(NAME2) NULL};
const char *const pfx_falloff_names[] = {PFX_FALLOFF_KINDS(NAME2) NULL};
const char *const pfx_force_space_names[] = {PFX_FORCE_SPACES(NAME2) NULL};
const char *const pfx_direction_mode_names[] = {PFX_DIRECTION_MODES(NAME2) NULL};
const char *const pfx_region_names[] = {PFX_REGION_KINDS(NAME2) NULL};
const char *const pfx_rate_kind_names[] = {PFX_RATE_KINDS(NAME2) NULL};

void pfx_kind_list(const char *const *names, bool or_style, char *buf, size_t size) {
    size_t n = pfx_kind_count(names), used = 0;
    buf[0] = 0;
    for (size_t i = 0; i < n && used < size; i++) {
        const char *sep = i == 0 ? "" : (or_style && i == n - 1) ? " or " : ", ";
        int w = snprintf(buf + used, size - used, "%s%s", sep, names[i]);
        if (w < 0)
            break;
        used += (size_t)w;
    }
}

size_t pfx_kind_count(const char *const *names) {
    size_t n = 0;
    while (names[n])
        n++;
    return n;
}

const char *pfx_kind_name(const char *const *names, int i) {
    return i >= 0 && (size_t)i < pfx_kind_count(names) ? names[i] : "?";
}

int pfx_kind_find(const char *const *names, const char *s) {
    for (int i = 0; names[i]; i++)
        if (!strcmp(names[i], s))
            return i;
    return -1;
}
