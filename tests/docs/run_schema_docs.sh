#!/usr/bin/env bash
# The schema's annotations (tests/docs/check_schema_docs.py): every key's
# meaning and unit first, the same text as pfx lsp's hover, the forms after,
# and the colour's error message on every colour form.
#
#   bash run_schema_docs.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" schema_docs "$@"
tally "$(timeout 120 "$py" "$src/tests/docs/check_schema_docs.py" "$pfx" "$src" 2>&1)"
summary
