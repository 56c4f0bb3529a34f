/* The pure questions about an emitter's kill rules. */
#include "model/kill_rules.h"

bool pfx_kill_rules_empty(const pfx_kill_rules *k) {
    return k->bounds == PFX_BOUNDS_NONE && k->count == 0;
}

bool pfx_kill_needs_alpha(const pfx_kill_rules *k) {
    for (size_t i = 0; i < k->count; i++)
        if (k->rules[i].kind == PFX_KILL_ALPHA_BELOW)
            return true;
    return false;
}
