#!/usr/bin/env bash
# The schema in yaml-language-server, the server most editors' YAML support
# runs (tests/docs/check_yaml_language_server.py). Optional: skipped (77)
# where node or the server is missing. ./install-deps --test installs the
# pinned server (tests/docs/yaml-language-server/package-lock.json) into
# tests/docs/yaml-language-server/node_modules where npm is present.
#
#   bash run_yaml_language_server.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" yaml_language_server "$@"
server=$src/tests/docs/yaml-language-server/node_modules/yaml-language-server/bin/yaml-language-server
command -v node >/dev/null || skip "no node to run yaml-language-server"
[ -f "$server" ] || skip "no yaml-language-server (./install-deps --test installs it where npm is)"
"$pfx" schema >"$work/schema.json" || fail "pfx schema failed"
tally "$(timeout 120 "$py" "$src/tests/docs/check_yaml_language_server.py" "$server" \
    "$work/schema.json" "$src" 2>&1)"
summary
