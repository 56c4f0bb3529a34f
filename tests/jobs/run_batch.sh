#!/usr/bin/env bash
# Batch rendering: several FILEs each into DIR/<name>/, -j N threads over
# the frames with files byte for byte those of -j 1, the exit status the
# worst of all, and --keep-going.
#
#   bash run_batch.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" batch "$@"
cd "$work" || exit 2
A=(--size 40x40 --frames 0:8 --seed 2 -q)
FIRE=$src/effects/fire.yaml
SMOKE=$src/effects/smoke.yaml
printf 'pfx: 1\nduration: -1\n' >broken.yaml

begin "two files render each into DIR/<name>/"
pfx_run render "$FIRE" "$SMOKE" -o j1 "${A[@]}"
want_status 0
[ "$(ls j1)" = "$(printf 'fire\nsmoke')" ] || flunk "j1 holds: $(ls j1 | tr '\n' ' ')"
[ "$(ls j1/fire/fire_*.png | wc -l)" = 9 ] && [ "$(ls j1/smoke/smoke_*.png | wc -l)" = 9 ] || flunk "not 9 frames each"
[ -f j1/fire/fire.manifest.json ] && [ -f j1/smoke/smoke.manifest.json ] || flunk "a manifest is missing"
end

for j in 2 3 16; do
    begin "-j $j writes the bytes of -j 1"
    pfx_run render "$FIRE" "$SMOKE" -o j$j "${A[@]}" -j $j
    want_status 0
    for f in j1/*/*.png j1/*/*.manifest.json; do
        cmp -s "$f" "j$j/${f#j1/}" || flunk "${f#j1/} differs"
    done
    [ "$(cd j$j && find . -type f | sort)" = "$(cd j1 && find . -type f | sort)" ] || flunk "other files"
    end
done

begin "a failure stops the files after it"
pfx_run render "$FIRE" broken.yaml "$SMOKE" -o stop "${A[@]}"
want_status 1
stderr_has "stopped after 'broken.yaml' failed; 1 file not rendered (--keep-going renders them)"
[ -d stop/fire ] && [ ! -e stop/smoke ] || flunk "rendered: $(ls stop | tr '\n' ' ')"
end

begin "--keep-going renders the rest; the status is the worst"
pfx_run render "$FIRE" broken.yaml "$SMOKE" -o keep "${A[@]}" --keep-going -j 2
want_status 1
[ "$(ls keep/smoke/smoke_*.png | wc -l)" = 9 ] || flunk "smoke was not rendered"
end

begin "a usage error in the middle is status 2, the worst"
pfx_run render "$FIRE" "$SMOKE" -o late "${A[@]}" --frames 500:600 --keep-going
want_status 2
end

begin "two effects of one name are refused"
mkdir -p other && cp "$FIRE" other/
pfx_run render "$FIRE" other/fire.yaml -o same "${A[@]}"
want_status 2
stderr_has "two effects would render into 'fire': rename one"
end

begin "--depfile with several files is refused"
pfx_run render "$FIRE" "$SMOKE" -o dep "${A[@]}" --depfile dep.d
want_status 2
stderr_has "--depfile names one target: give one FILE"
end

begin "-j 0 is a usage error"
pfx_run render "$FIRE" -o z "${A[@]}" -j 0
want_status 2
stderr_has "-j takes a number of threads from 1 to 256, got '0'"
end

summary
