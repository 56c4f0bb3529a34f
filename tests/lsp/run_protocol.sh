#!/bin/bash
# pfx lsp over stdio: scripted sessions (tests/lsp/protocol.py) with the
# expected response of every capability on files with known answers, the
# lifecycle and framing errors included.
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" lsp_protocol "$@"

tally "$(timeout 300 "$py" "$src/tests/lsp/protocol.py" "$pfx" "$src" 2>&1)"
summary
