#!/bin/bash
# pfx lsp over stdio: scripted sessions (tests/lsp/protocol.py) with the
# expected response of every capability on files with known answers, the
# lifecycle and framing errors included.
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" lsp_protocol "$@"

report=$(timeout 300 "$py" "$src/tests/lsp/protocol.py" "$pfx" "$src" 2>&1)
status=$?
tally "$report"
# A check that raised (a position its text no longer has) ends the script
# early: the checks after it did not run, which is a failure, not a pass.
[ "$status" -eq 0 ] || [ "$failed" -gt 0 ] || fail "protocol.py stopped with status $status"
summary
