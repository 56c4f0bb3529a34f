# pfx preview's HTTP contract without a browser (check_server.py): the URL
# line, loopback, token, Host, paths, frames equal to pfx render, live
# reload, diagnostics, pick, 200 edits, a port in use, Control-C.
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" preview_server "$@"
tally "$("$py" "$src/tests/preview/check_server.py" "$pfx" "$src" "$work" 2>&1)"
summary
