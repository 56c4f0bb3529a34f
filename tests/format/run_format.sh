#!/bin/bash
# Every C source and header the repository tracks is formatted as
# .clang-format says (STYLE.md: CI checks the format). One check per file.
#
#   bash run_format.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" format "$@"
cd "$src" || exit 2
if ! command -v clang-format >/dev/null; then
    fail "clang-format is missing (./install-deps --test)"
    summary
    exit
fi
while read -r f; do
    if clang-format --dry-run -Werror "$f" >/dev/null 2>&1; then
        pass "$f"
    else
        fail "$f is not clang-formatted (clang-format -i $f)"
    fi
done < <(git ls-files '*.c' '*.h' 2>/dev/null || find src tests -name '*.[ch]')
summary
