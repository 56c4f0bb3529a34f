#!/usr/bin/env bash
# Determinism of the whole pipeline, byte for byte: the same render twice is
# identical; a --frames slice equals the same frames of the full render (the
# fixed-step simulation does not depend on where the output starts); the
# same for the particle bake; the OSMesa thread count does not change the
# pixels. A different --seed must change the output, which shows the
# comparisons can fail.
#
# usage: bash run_determinism.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" determinism "$@"
fire=$src/effects/fire.yaml
smoke=$src/effects/smoke.yaml
small=(--size 128x128)

# same_frames DIR_A DIR_B STEM FIRST LAST: frames FIRST..LAST exist in both
# and are byte-identical; prints the first difference.
same_frames() {
    local a=$1 b=$2 stem=$3 f name
    for ((f = $4; f <= $5; f++)); do
        printf -v name '%s_%04d.png' "$stem" "$f"
        if [[ ! -f $a/$name || ! -f $b/$name ]]; then
            echo "  missing $name" >&2
            return 1
        fi
        if ! cmp -s "$a/$name" "$b/$name"; then
            echo "  $a/$name and $b/$name differ" >&2
            return 1
        fi
    done
}

# count_pngs DIR: the number of PNG files in DIR.
count_pngs() { find "$1" -maxdepth 1 -name '*.png' | wc -l; }

# ---- Renders of fire.yaml (additive) ----
if run fire_a "$pfx" render "$fire" -o "$work/fire_a" "${small[@]}" --frames 0:9 &&
    run fire_b "$pfx" render "$fire" -o "$work/fire_b" "${small[@]}" --frames 0:9; then
    n=$(count_pngs "$work/fire_a")
    if [[ $n -eq 10 ]] && same_frames "$work/fire_a" "$work/fire_b" fire 0 9; then
        pass "fire: two renders of frames 0:9 are byte-identical"
    else
        fail "fire: two renders of frames 0:9 are byte-identical" "$n PNGs"
    fi
else
    fail "fire: render frames 0:9 twice" "pfx failed"
fi

if run fire_slice "$pfx" render "$fire" -o "$work/fire_slice" "${small[@]}" --frames 4:6; then
    n=$(count_pngs "$work/fire_slice")
    if [[ $n -eq 3 ]] && same_frames "$work/fire_slice" "$work/fire_a" fire 4 6; then
        pass "fire: --frames 4:6 equals frames 4..6 of the full render"
    else
        fail "fire: --frames 4:6 equals frames 4..6 of the full render" "$n PNGs"
    fi
else
    fail "fire: render --frames 4:6" "pfx failed"
fi

# ---- Renders of smoke.yaml (alpha blending, depth-sorted) ----
if run smoke_a "$pfx" render "$smoke" -o "$work/smoke_a" "${small[@]}" --frames 0:9 &&
    run smoke_b "$pfx" render "$smoke" -o "$work/smoke_b" "${small[@]}" --frames 0:9 &&
    run smoke_slice "$pfx" render "$smoke" -o "$work/smoke_slice" "${small[@]}" --frames 5:8; then
    if same_frames "$work/smoke_a" "$work/smoke_b" smoke 0 9; then
        pass "smoke: two renders of frames 0:9 are byte-identical"
    else
        fail "smoke: two renders of frames 0:9 are byte-identical"
    fi
    n=$(count_pngs "$work/smoke_slice")
    if [[ $n -eq 4 ]] && same_frames "$work/smoke_slice" "$work/smoke_a" smoke 5 8; then
        pass "smoke: --frames 5:8 equals frames 5..8 of the full render"
    else
        fail "smoke: --frames 5:8 equals frames 5..8 of the full render" "$n PNGs"
    fi
else
    fail "smoke: renders" "pfx failed"
fi

# ---- Bakes ----
if run bake_a "$pfx" bake "$fire" -o "$work/bake_a.csv" &&
    run bake_b "$pfx" bake "$fire" -o "$work/bake_b.csv" &&
    run bake_slice "$pfx" bake "$fire" -o "$work/bake_slice.csv" --frames 3:5; then
    rows=$(($(wc -l <"$work/bake_a.csv") - 1))
    if [[ $rows -gt 0 ]] && cmp -s "$work/bake_a.csv" "$work/bake_b.csv"; then
        pass "fire: two full bakes are byte-identical ($rows rows)"
    else
        fail "fire: two full bakes are byte-identical" "$rows rows"
    fi
    # The slice: the same header, then exactly the full bake's rows whose
    # frame (first column) is 3, 4 or 5.
    awk -F, 'NR == 1 || ($1 >= 3 && $1 <= 5)' "$work/bake_a.csv" >"$work/bake_a_3_5.csv"
    rows=$(($(wc -l <"$work/bake_slice.csv") - 1))
    if [[ $rows -gt 0 ]] && cmp -s "$work/bake_slice.csv" "$work/bake_a_3_5.csv"; then
        pass "fire: bake --frames 3:5 equals the full bake's rows for frames 3..5 ($rows rows)"
    else
        fail "fire: bake --frames 3:5 equals the full bake's rows for frames 3..5" "$rows rows"
        diff "$work/bake_slice.csv" "$work/bake_a_3_5.csv" | head -5 >&2
    fi
else
    fail "fire: bakes" "pfx failed"
fi

# ---- A different seed changes the output (the comparisons can fail) ----
if run fire_seed "$pfx" render "$fire" -o "$work/fire_seed" "${small[@]}" --frames 0:9 --seed 8 &&
    run bake_seed "$pfx" bake "$fire" -o "$work/bake_seed.csv" --frames 3:5 --seed 8; then
    differ=0
    for f in "$work"/fire_a/fire_*.png; do
        cmp -s "$f" "$work/fire_seed/${f##*/}" || differ=$((differ + 1))
    done
    if [[ $differ -gt 0 ]]; then
        pass "fire: --seed 8 changes the render ($differ of 10 frames differ)"
    else
        fail "fire: --seed 8 changes the render" "every frame identical to seed 7"
    fi
    if ! cmp -s "$work/bake_seed.csv" "$work/bake_slice.csv"; then
        pass "fire: --seed 8 changes the bake"
    else
        fail "fire: --seed 8 changes the bake" "identical to seed 7"
    fi
else
    fail "fire: --seed 8" "pfx failed"
fi

# ---- The rasteriser's thread count does not change the pixels ----
for effect in fire smoke; do
    if run "${effect}_t1" env LP_NUM_THREADS=1 "$pfx" render "$src/effects/$effect.yaml" \
        -o "$work/${effect}_t1" "${small[@]}" --frames 0:9; then
        if same_frames "$work/${effect}_t1" "$work/${effect}_a" "$effect" 0 9; then
            pass "$effect: LP_NUM_THREADS=1 gives the same PNGs as the default"
        else
            fail "$effect: LP_NUM_THREADS=1 gives the same PNGs as the default"
        fi
    else
        fail "$effect: render with LP_NUM_THREADS=1" "pfx failed"
    fi
done

summary
