#!/usr/bin/env bash
# The bytes of pfx bake, pinned: the SHA-256 of CSV, PLY and pcache bakes of
# three effects (fire: three emitters; campfire: five; explosion: 400
# sparks, more than one block of jobs/bake_view.c's rows),
# recorded with the pfx of 954f29e, before the writers took plain rows
# (output/bake.c read the sim pools itself then). The row view must hand
# the writers the same rows in the same order, so every file is unchanged,
# whether written to a file or to standard output. And output/ includes no
# sim/ header.
#
# Like tests/unit/test_sim.c's EXPECTED_HASH, a change here means bakes
# changed: a commit that changes the simulation on purpose updates these
# and says why. Re-recorded for the examples reworked for issue 26 (new
# sizes, colours, rates and textures in fire, campfire and explosion), by
# a pfx whose row view and writers were unchanged; each pinned effect keeps
# the emitter count and particle numbers that make it worth pinning.
#
#   bash run_bake_pinned.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" bake_pinned "$@"
# The PLY and pcache headers name the effect's path as given: relative to
# the source tree, so that the bytes do not depend on where it is checked
# out.
cd "$src" || exit 2

# effect frames format sha256
pinned=(
    "fire 10:14 csv 5392da3892db64b6f053035f2fa08e6b55b4459dccf978b2613d7270cb8b02f0"
    "fire 10:14 ply 525e96a3b0f79e86494bc197657990cf11902f9bb7d5d38c83fba627aef8069b"
    "fire 10:14 pcache eafa3b87a7e3654b0f28489a63a034936bd915854ee19a0f83af27e66fb79e3d"
    "campfire 28:30 csv fecb95ca1b7f91be650ba71d2fce0cf4fa825a20b7637a411b8b11607937c60b"
    "campfire 28:30 ply fe54ad8afcab11a457d13151ed3549e2b8c2b8daf48804d3d1ee959d1500bb22"
    "campfire 28:30 pcache 5e79e5dd00192f99a6d14fa27dd22df1a95d3ca92b01dac20b5f2e44e92f3973"
    "explosion 6:8 csv 9da189a0a6ba50d6c1216dc9ca8e790d60a935ea34e919cc3b71cf4aef1305cf"
    "explosion 6:8 ply df9b32735629983f2480fa5bdabddddf131bc17969f9221402f36a2948a2fcb6"
    "explosion 6:8 pcache 20c2288751761f5d415ab881021eadaf2b861ba68de23b0a021d7eba1f4064d5"
)

for p in "${pinned[@]}"; do
    read -r effect frames format want <<<"$p"
    begin "$effect --frames $frames as $format: the bytes pinned before the row view"
    pfx_run bake "effects/$effect.yaml" -o "$work/$effect.$format" --frames "$frames" \
        --seed 3 -q
    if finished && want_status 0; then
        got=$(sha256sum <"$work/$effect.$format" | cut -d' ' -f1)
        [ "$got" = "$want" ] || flunk "sha256 $got"
    fi
    pfx_run bake "effects/$effect.yaml" -o - --format "$format" --frames "$frames" \
        --seed 3 -q
    if finished && want_status 0; then
        cmp -s "$work/out" "$work/$effect.$format" || flunk "-o - differs from the file"
    fi
    end
done

# The arrow the row view ends: output/ writes rows and pixels and reads no
# simulation (ARCHITECTURE.md), so none of its files includes a sim/ header.
begin "src/output/ includes no sim/ header"
hits=$(grep -n '#include "sim/' "$src"/src/output/*.[ch])
[ -z "$hits" ] || flunk "$hits"
end

summary
