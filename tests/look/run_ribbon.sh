#!/usr/bin/env bash
# Ribbons with known answers through `pfx render`: a trail's strip width in
# pixels, its extent, that it has no gaps, colour over life along it, the
# round cross-section, one strip per parent, and byte-identical reruns and
# --frames slices. The scenes and the formulas are in check_ribbon.py.
#
# usage: bash run_ribbon.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" ribbon "$@"
tally "$("$py" "$src/tests/look/check_ribbon.py" "$pfx" "$work" 2>&1)"
summary
