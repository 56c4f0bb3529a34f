#!/usr/bin/env bash
# egl-gpu against egl-cpu: a GPU rasterises and rounds a little differently
# from llvmpipe, so its frames are held to a tolerance instead of byte
# identity: every channel within 3/255 of the egl-cpu frame, and at most 1%
# of all channel values different at all. The sprites' falloff reaches 0
# with zero slope at the rim, so a pixel that one rasteriser covers and the
# other does not changes by almost nothing; what is left is float rounding.
# Colour is compared premultiplied by alpha (compare_frames.py says why).
# Frames are 512x512, the effects' own size: at 96x96 the flipbook sprites
# are minified many times over, and the GL specification lets each
# implementation approximate the mipmap level it samples (measured on an
# H100 against llvmpipe: up to 26/255 apart at 96x96 in campfire, 2/255
# at 512x512).
#
# Where there is no GPU EGL device (pfx says so in one line) it checks the
# comparison itself on egl-cpu frames (the same frames are within the
# tolerance, frames of another seed are not) and then skips (exit 77,
# CTest's skip): the GPU's frames, what the test is for, were not checked.
#
# usage: bash run_egl_gpu.sh PATH-TO-PFX SOURCE-DIR
set -u

pfx=${1:?usage: run_egl_gpu.sh PATH-TO-PFX SOURCE-DIR}
src=${2:?usage: run_egl_gpu.sh PATH-TO-PFX SOURCE-DIR}
python=/usr/bin/python3
max_diff=3        # out of 255, per channel
max_fraction=0.01 # of all channel values
cases=(fire:0:1 smoke:0:1 explosion:8:9 campfire:30:31 rain:10:11 shockwave:8:9
    sword_swipe:4:5)
small=(--size 512x512 -q)

source "$src/tests/harness.sh" egl-gpu "$@"

# compare REF OTHER: the comparison of two folders of frames, within the
# tolerance; its report goes to $work/compare.out.
compare() {
    PYTHONPATH="$src/tests" "$python" "$src/tests/gpu/compare_frames.py" "$1" "$2" \
        "$max_diff" "$max_fraction" >"$work/compare.out" 2>&1
}

if ! "$pfx" render "$src/effects/fire.yaml" -o "$work/probe" --size 8x8 --frames 0:0 -q \
    --renderer egl-cpu 2>"$work/probe.err"; then
    if grep -q "not built into this pfx" "$work/probe.err"; then
        skip "$(cat "$work/probe.err")"
    fi
    fail "egl-cpu renders" "$(cat "$work/probe.err")"
fi

# The reference frames, and the comparison checked on them.
for c in "${cases[@]}"; do
    IFS=: read -r e first last <<<"$c"
    run "$e-cpu" "$pfx" render "$src/effects/$e.yaml" -o "$work/cpu" "${small[@]}" \
        --frames "$first:$last" --renderer egl-cpu || fail "$e: render --renderer egl-cpu"
done
run seed "$pfx" render "$src/effects/smoke.yaml" -o "$work/seed" "${small[@]}" --frames 0:3 \
    --renderer egl-cpu --seed 8 || fail "smoke: render --seed 8"
mkdir -p "$work/cpu-smoke"
cp "$work"/cpu/smoke_*.png "$work/cpu-smoke/" 2>/dev/null
if compare "$work/cpu" "$work/cpu"; then
    pass "the comparison accepts identical frames"
else
    fail "the comparison accepts identical frames" "$(cat "$work/compare.out")"
fi
if compare "$work/cpu-smoke" "$work/seed"; then
    fail "the comparison rejects frames of another seed" "$(cat "$work/compare.out")"
elif grep -q '^all: ' "$work/compare.out"; then
    pass "the comparison rejects frames of another seed ($(sed -n 's/^all: //p' "$work/compare.out"))"
else
    fail "the comparison rejects frames of another seed" "$(cat "$work/compare.out")"
fi

# The GPU, where there is one.
"$pfx" render "$src/effects/fire.yaml" -o "$work/gpu-probe" --size 8x8 --frames 0:0 -q \
    --renderer egl-gpu 2>"$work/gpu-probe.err"
status=$?
if [[ $status -eq 1 ]] && grep -qE "renderer 'egl-gpu': (no GPU EGL device|libEGL cannot list devices)" \
    "$work/gpu-probe.err"; then
    skip "$(cat "$work/gpu-probe.err")"
fi
if [[ $status -ne 0 ]]; then
    fail "egl-gpu starts where a GPU EGL device exists" "status $status: $(cat "$work/gpu-probe.err")"
    summary
    exit
fi
for c in "${cases[@]}"; do
    IFS=: read -r e first last <<<"$c"
    run "$e-gpu" "$pfx" render "$src/effects/$e.yaml" -o "$work/gpu" "${small[@]}" \
        --frames "$first:$last" --renderer egl-gpu || fail "$e: render --renderer egl-gpu"
done
if compare "$work/cpu" "$work/gpu"; then
    pass "egl-gpu frames are within the tolerance of egl-cpu's: $(sed -n 's/^all: //p' "$work/compare.out")"
else
    fail "egl-gpu frames are within the tolerance of egl-cpu's" "$(cat "$work/compare.out")"
fi

summary
