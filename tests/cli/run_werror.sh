#!/usr/bin/env bash
# --werror: an effect with a warning fails (exit 1) after its warning is
# printed, for validate, render and bake; without it the same file passes.
#
#   bash run_werror.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" werror "$@"
cd "$work" || exit 2
W=$src/tests/diag/no_emitters_warning.yaml

begin "validate passes a warning without --werror"
pfx_run validate "$W"
want_status 0
stderr_has "warning: the effect has no 'emitters'"
stderr_has "pfx: validated '$W': 1 warning"
end

begin "validate --werror fails on it"
pfx_run validate --werror "$W"
want_status 1
stderr_has "warning: the effect has no 'emitters'"
stderr_has "pfx: '$W': 1 warning treated as error (--werror)"
! grep -qF "pfx: validated" "$work/err" || flunk "a summary line after a failure"
end

begin "bake --werror writes nothing"
pfx_run bake "$W" -o w.csv --werror
want_status 1
[ ! -e w.csv ] || flunk "w.csv was written"
end

begin "validate --werror passes a warning the file allows"
pfx_run validate --werror "$src/tests/diag/allow_loop_seam.yaml"
want_status 0
stderr_has "no warnings, 1 allowed"
! grep -qF "warning:" "$work/err" || flunk "an allowed warning was printed"
end

begin "render --werror renders an effect whose warning is allowed"
pfx_run render --werror "$src/tests/diag/allow_loop_seam.yaml" -o frames --frames 0 -q
want_status 0
[ -e frames/allow_loop_seam_0000.png ] || flunk "no frame: $(ls frames 2>&1)"
end

begin "validate --werror passes a clean file"
pfx_run validate --werror "$src/effects/fire.yaml"
want_status 0
end

summary
