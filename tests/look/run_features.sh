#!/usr/bin/env bash
# The look features of issue 26 with known answers through `pfx bake` and
# `pfx render`: tangent emission, tapered ribbons. The scenes and the
# formulas are in check_features.py.
#
# usage: bash run_features.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" features "$@"
tally "$("$py" "$src/tests/look/check_features.py" "$pfx" "$work" 2>&1)"
summary
