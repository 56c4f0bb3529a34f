#!/bin/bash
# A real client: Debian's neovim, headless, with its built-in LSP client
# on pfx lsp (tests/lsp/neovim.lua): the typo's diagnostic at pfx
# validate's line:col with its rule id, hover with the unit, completion of
# the file's force names, a code action that fixes the typo, after which
# the diagnostics clear. Skips where nvim is not installed.
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" lsp_neovim "$@"

command -v nvim >/dev/null 2>&1 || skip "neovim is not installed (./install-deps --test)"

effect=$work/fire.yaml
# The first emitter's forces misspelt: error PFX4001, did you mean 'gravity'.
sed '0,/forces: \[gravity, flicker\]/s//forces: [gravty, flicker]/' "$src/effects/fire.yaml" >"$effect"
cp -r "$src/effects/textures" "$work/"
pfx_run validate "$effect"
where=$(sed -n 's/^[^:]*:\([0-9]*\):\([0-9]*\): error: .*\[PFX4001\]$/\1 \2/p' "$work/err" | head -1)
if [ -z "$where" ]; then
    fail "pfx validate reports the typo" "$(cat "$work/err")"
    summary
    exit
fi
read -r line col <<<"$where"
HOME=$work XDG_CONFIG_HOME=$work XDG_DATA_HOME=$work XDG_STATE_HOME=$work \
    PFX=$pfx EFFECT=$effect WANT_LINE=$line WANT_COL=$col REPORT=$work/report \
    timeout 60 nvim --headless --clean -u NONE -i NONE -n \
    -c "luafile $src/tests/lsp/neovim.lua" >"$work/nvim.log" 2>&1
[ -s "$work/report" ] || echo "FAIL neovim: no report ($(head -c 400 "$work/nvim.log"))" >"$work/report"
tally "$(cat "$work/report")"
summary
