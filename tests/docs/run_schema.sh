#!/usr/bin/env bash
# The committed schema is what `pfx schema` prints: the key tables are the
# one source of the format's keys, and schemas/pfx-effect.schema.json must
# not drift from them (regenerate it with `pfx schema > schemas/...`).
#
#   bash run_schema.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" schema "$@"
if ! "$pfx" schema >"$work/schema.json"; then
    fail "pfx schema failed"
elif cmp -s "$work/schema.json" "$src/schemas/pfx-effect.schema.json"; then
    pass "schemas/pfx-effect.schema.json is what pfx schema prints"
else
    fail "schemas/pfx-effect.schema.json differs from pfx schema" \
        "$(diff "$src/schemas/pfx-effect.schema.json" "$work/schema.json" | head -20)"
fi
summary
