#!/usr/bin/env bash
# Every effect shown in the documentation is one pfx accepts without a
# warning: each ```yaml block of README.md, and each example block (.EX ..
# .EE) of man/pfx.1 and man/pfx-effect.5 that is a YAML document (its first
# line is `pfx: <version>` or a comment, not a #! line), except the SYNOPSIS grammar of pfx-effect.5
# (placeholders, not YAML) and the DIAGNOSTICS of pfx.1 (a broken file on
# purpose, whose exact diagnostics run_docs.sh checks). A test that finds no
# block fails, so a change to the extraction cannot pass by finding none.
#
#   bash run_doc_blocks.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" doc_blocks "$@"

# README.md: the lines between ```yaml and ```, one file per block.
awk -v dir="$work" '
    /^```yaml[[:space:]]*$/ { n++; on = 1; file = sprintf("%s/readme-%d.yaml", dir, n); printf "" >file; next }
    on && /^```/ { on = 0; close(file); next }
    on { print >file }
' "$src/README.md"

# The man pages: de-roffed example blocks that start like a YAML document.
man_blocks() {
    local page=$1 prefix=$2
    awk -v dir="$work" -v prefix="$prefix" '
        /^\.SH / { sec = substr($0, 5); gsub(/"/, "", sec); next }
        /^\.EX/ { inex = 1; first = 1; next }
        /^\.EE/ { if (file != "") close(file); inex = 0; file = ""; next }
        !inex { next }
        first {
            first = 0
            if (sec == "SYNOPSIS" || sec == "DIAGNOSTICS" || $0 !~ /^(pfx: *[0-9]|#)/ || $0 ~ /^#!/) { inex = 0; next }
            n++
            file = sprintf("%s/%s-%s-%d.yaml", dir, prefix, sec, n)
            gsub(/ /, "_", file)
        }
        { print >file }
    ' "$page"
}
man_blocks "$src/man/pfx.1" man1
man_blocks "$src/man/pfx-effect.5" man5
for f in "$work"/*.yaml; do
    [ -e "$f" ] || continue
    sed -i -e 's/\\-/-/g' -e 's/\\(dq/"/g' -e 's/\\(aq/'"'"'/g' -e 's/\\(ha/^/g' \
        -e 's/\\(ti/~/g' -e 's/\\&//g' -e 's/\\e/\\/g' "$f"
done

count_readme=$(find "$work" -name 'readme-*.yaml' | wc -l)
count_man=$(find "$work" -name 'man*.yaml' | wc -l)
[ "$count_readme" -ge 2 ] && pass "README.md has $count_readme yaml blocks" ||
    fail "found $count_readme yaml blocks in README.md, expected at least 2"
[ "$count_man" -ge 2 ] && pass "the man pages have $count_man effect examples" ||
    fail "found $count_man effect examples in the man pages, expected at least 2"

# Relative mesh paths in the examples name files of effects/; textures are
# read beside the effect, so effects/textures is linked beside the blocks.
ln -s "$src/effects/textures" "$work/textures"
for f in "$work"/*.yaml; do
    [ -e "$f" ] || continue
    name=${f##*/}
    begin "$name validates without a diagnostic"
    (cd "$src/effects" && timeout 60 "$pfx" validate -q "$f") >"$work/out" 2>"$work/err"
    status=$?
    want_status 0
    [ ! -s "$work/err" ] || flunk "$(head -c 600 "$work/err")"
    end
done
summary
