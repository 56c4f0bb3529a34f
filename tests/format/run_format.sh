#!/bin/bash
# Every C source and header the repository tracks is formatted as
# .clang-format says (STYLE.md: CI checks the format).
set -u
src=$2
cd "$src" || exit 1
command -v clang-format >/dev/null || { echo "clang-format is missing (./install-deps --test)"; exit 1; }
passed=0 failed=0
while read -r f; do
    if clang-format --dry-run -Werror "$f" >/dev/null 2>&1; then
        passed=$((passed + 1))
    else
        echo "FAIL $f is not clang-formatted (clang-format -i $f)"
        failed=$((failed + 1))
    fi
done < <(git ls-files '*.c' '*.h' 2>/dev/null || find src tests -name '*.[ch]')
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
