#!/usr/bin/env bash
# egl-gpu against egl-cpu: a GPU rasterises and rounds a little differently
# from llvmpipe, so its frames are held to a tolerance instead of byte
# identity: every channel within 3/255 of the egl-cpu frame, and at most 1%
# of all channel values different at all. The sprites' falloff reaches 0
# with zero slope at the rim, so a pixel that one rasteriser covers and the
# other does not changes by almost nothing; what is left is float rounding.
# Colour is compared premultiplied by alpha (compare_frames.py says why).
# Frames are compared at 512x512, the effects' own size, and at 96x96,
# where the flipbook sprites are minified many times over: sprites pass
# their mip level explicitly (render/shader.c), so the two must agree
# there too (with the level left to each implementation, an H100 was
# 26/255 from llvmpipe at 96x96 in campfire, 2/255 at 512x512).
#
# PFX_GPU_TEST_RENDERER=egl-cpu rehearses the whole test where there is no
# GPU: the "GPU" frames are then egl-cpu's again, and must match exactly.
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
sizes=(512x512 96x96)
gpu=${PFX_GPU_TEST_RENDERER:-egl-gpu}

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

# render RENDERER DIR: every case at every size into DIR/<size>.
render() {
    local c e first last size
    for size in "${sizes[@]}"; do
        for c in "${cases[@]}"; do
            IFS=: read -r e first last <<<"$c"
            run "$e-$1-$size" "$pfx" render "$src/effects/$e.yaml" -o "$2/$size" --size "$size" \
                -q --frames "$first:$last" --renderer "$1" || fail "$e: render --renderer $1 --size $size"
        done
    done
}

# The reference frames, and the comparison checked on them.
render egl-cpu "$work/cpu"
run seed "$pfx" render "$src/effects/smoke.yaml" -o "$work/seed" --size 512x512 -q --frames 0:3 \
    --renderer egl-cpu --seed 8 || fail "smoke: render --seed 8"
mkdir -p "$work/cpu-smoke"
cp "$work"/cpu/512x512/smoke_*.png "$work/cpu-smoke/" 2>/dev/null
if compare "$work/cpu/512x512" "$work/cpu/512x512"; then
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
    --renderer "$gpu" 2>"$work/gpu-probe.err"
status=$?
if [[ $status -eq 1 ]] && grep -qE "renderer 'egl-gpu': (no GPU EGL device|libEGL cannot list devices)" \
    "$work/gpu-probe.err"; then
    skip "$(cat "$work/gpu-probe.err")"
fi
if [[ $status -ne 0 ]]; then
    fail "$gpu starts where a GPU EGL device exists" "status $status: $(cat "$work/gpu-probe.err")"
    summary
    exit
fi
render "$gpu" "$work/gpu"
for size in "${sizes[@]}"; do
    if compare "$work/cpu/$size" "$work/gpu/$size"; then
        pass "$gpu frames at $size are within the tolerance of egl-cpu's: $(sed -n 's/^all: //p' "$work/compare.out")"
    else
        fail "$gpu frames at $size are within the tolerance of egl-cpu's" "$(cat "$work/compare.out")"
    fi
    # Rehearsed on egl-cpu, the same renderer twice: nothing may differ.
    if [[ $gpu == egl-cpu ]] && ! grep -q '^all: largest difference 0/255' "$work/compare.out"; then
        fail "egl-cpu twice at $size gives the same frames" "$(cat "$work/compare.out")"
    fi
done

summary
