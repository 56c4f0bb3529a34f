#!/usr/bin/env bash
# What a sprite looks like, with known answers through `pfx render`:
# texture orientation, flipbook cells at mid-cell ages, a stretched
# sprite's extent, sub-pixel brightness, premultiplied against straight
# alpha, the tone curves at a pixel, and motion blur's streak and
# brightness. The scenes and the formulas are in check_look.py.
#
# usage: bash run_look.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" look "$@"
tally "$("$py" "$src/tests/look/check_look.py" "$pfx" "$work" 2>&1)"
summary
