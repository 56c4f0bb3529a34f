#!/usr/bin/env bash
# The mip level a textured sprite reads, with known answers through `pfx
# render`: a texture whose mip levels differ in which channels are striped,
# drawn at sizes that need whole levels 0 to 3, between levels 1 and 2
# (nearest, and the blend across half-way), as a flipbook cell, tilted out
# of the view plane, and on a ribbon. The scenes and the formulas are in
# check_mip.py.
#
# usage: bash run_mip.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" mip "$@"
tally "$("$py" "$src/tests/look/check_mip.py" "$pfx" "$work" 2>&1)"
summary
