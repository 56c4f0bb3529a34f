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
# Every "#/$defs/x" names a definition: yaml-language-server resolves them
# all when it loads the schema and drops the whole schema on one it cannot
# (python's jsonschema only resolves the ones an example reaches).
if missing=$("$py" - "$src/schemas/pfx-effect.schema.json" <<'PY'
import json, sys
schema = json.load(open(sys.argv[1]))
def refs(node):
    if isinstance(node, dict):
        for k, v in node.items():
            if k == "$ref":
                yield v
            yield from refs(v)
    elif isinstance(node, list):
        for v in node:
            yield from refs(v)
bad = sorted({r for r in refs(schema)
              if not r.startswith("#/$defs/") or r[len("#/$defs/"):] not in schema["$defs"]})
print(" ".join(bad))
sys.exit(1 if bad else 0)
PY
); then
    pass "every \$ref of the schema names a definition"
else
    fail "the schema refers to definitions it lacks" "$missing"
fi
summary
