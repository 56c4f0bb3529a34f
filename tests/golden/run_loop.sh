#!/usr/bin/env bash
# Seamless loops: effects/fire_loop.yaml has `loop: true`, so the whole
# effect is periodic with period `duration` and frame N = duration x fps is
# frame 0 again, byte for byte (and frame N + 5 is frame 5). Byte equality
# of the period's ends is not yet "no visible seam": the last frame of the
# period, N - 1, must lead into frame 0 as smoothly as any frame leads into
# the next inside the loop, measured as the mean absolute difference of the
# pixels (8-bit RGBA, decoded in pure Python by tests/png_rgba.py).
#
# The same effect with `loop: false` (a temporary copy, its duration
# doubled so that frame N exists; its emitters run without end either way)
# must fail both checks, which shows they can fail: it starts empty, so its
# frame N is not its frame 0 and the jump from frame N - 1 back to frame 0
# is far larger than any step inside the clip.
#
# usage: bash run_loop.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" loop "$@"
effect=$src/effects/fire_loop.yaml
small=(--size 128x128)
# The seam may be at most this many times the largest step inside the loop.
tolerance=1.5

# frame DIR STEM K: the path of frame K's PNG.
frame() { printf '%s/%s_%04d.png' "$1" "$2" "$3"; }

# top_number KEY FILE: the value of a top-level `KEY: number` line.
top_number() { sed -n "s/^$1:[[:space:]]*\([0-9.]*\).*/\1/p" "$2" | head -n 1; }

# seam.py DIR STEM N TOLERANCE: prints "seam MAX K" (the mean absolute
# difference of frames N-1 and 0, the largest of frames k and k+1 for k in
# 0..N-2, and that k) and exits 0 when seam <= TOLERANCE x MAX, 1 when not,
# 2 on a PNG it cannot read.
cat >"$work/seam.py" <<'EOF'
import sys
import zlib

from png_rgba import decode


def mad(a, b):
    """Mean absolute difference over every channel of two same-size images."""
    if len(a) != len(b):
        raise ValueError("frames differ in size")
    return sum(abs(x - y) for x, y in zip(a, b)) / len(a)


def main():
    folder, stem, n, tol = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
    try:
        img = [decode(f"{folder}/{stem}_{k:04d}.png")[2] for k in range(n)]
    except (OSError, ValueError, zlib.error) as e:
        print(f"cannot read the frames: {e}", file=sys.stderr)
        return 2
    steps = [mad(img[k], img[k + 1]) for k in range(n - 1)]
    worst = max(range(n - 1), key=lambda k: steps[k])
    seam = mad(img[n - 1], img[0])
    print(f"{seam:.4f} {steps[worst]:.4f} {worst}")
    return 0 if seam <= tol * steps[worst] else 1


sys.exit(main())
EOF

# ---- The period, from the effect file ----
duration=$(top_number duration "$effect")
fps=$(top_number fps "$effect")
n=$(awk -v d="${duration:-0}" -v f="${fps:-0}" 'BEGIN { printf "%d", d * f + 0.5 }')
if grep -q '^loop:[[:space:]]*true' "$effect" && [[ $n -ge 3 ]]; then
    pass "fire_loop: loops, duration $duration s x $fps fps = $n frames a period"
else
    fail "fire_loop: loops with a period of at least 3 frames" "loop: true, duration '$duration', fps '$fps'"
    summary
    exit
fi

# ---- The looping effect: no warnings, frame N = frame 0, N + 5 = 5 ----
if run validate "$pfx" validate -q "$effect" && [[ ! -s $work/validate.err && ! -s $work/validate.out ]]; then
    pass "fire_loop: pfx validate prints nothing (no loop warning)"
else
    fail "fire_loop: pfx validate prints nothing (no loop warning)" "$(head -c 300 "$work/validate.err")"
fi

last=$((n + 5))
if run loop "$pfx" render "$effect" -o "$work/loop" "${small[@]}" --frames "0:$last"; then
    for k in 0 5; do
        a=$(frame "$work/loop" fire_loop $((n + k)))
        b=$(frame "$work/loop" fire_loop "$k")
        if [[ -f $a && -f $b ]] && cmp -s "$a" "$b"; then
            pass "fire_loop: frame $((n + k)) is byte-identical to frame $k"
        else
            fail "fire_loop: frame $((n + k)) is byte-identical to frame $k"
        fi
    done
    if cmp -s "$(frame "$work/loop" fire_loop 0)" "$(frame "$work/loop" fire_loop 1)"; then
        fail "fire_loop: the frames change inside the loop" "frames 0 and 1 are identical"
    else
        pass "fire_loop: the frames change inside the loop (frame 1 is not frame 0)"
    fi
    # The seam: frame N - 1 -> frame 0 against every k -> k + 1 inside.
    result=$(PYTHONPATH="$src/tests" "$py" "$work/seam.py" "$work/loop" fire_loop "$n" "$tolerance")
    status=$?
    read -r seam worst at <<<"$result"
    if [[ $status -eq 0 ]]; then
        pass "fire_loop: no visible seam: frames $((n - 1))->0 differ by $seam, at most $tolerance x the largest step inside, $worst (frames $at->$((at + 1)))"
    elif [[ $status -eq 1 ]]; then
        fail "fire_loop: no visible seam" "frames $((n - 1))->0 differ by $seam, above $tolerance x $worst (frames $at->$((at + 1)))"
    else
        fail "fire_loop: no visible seam" "the seam check could not read the frames"
    fi
else
    fail "fire_loop: render --frames 0:$last" "pfx failed"
fi

# ---- The same effect with loop: false: both checks must fail ----
twice=$(awk -v d="$duration" 'BEGIN { print 2 * d }')
sed -e 's/^loop:[[:space:]]*true/loop: false/' -e "s/^duration:.*/duration: $twice/" \
    "$effect" >"$work/fire_once.yaml"
ln -s "$src/effects/textures" "$work/textures" # the copy's textures, relative to it
if ! grep -q '^loop: false' "$work/fire_once.yaml"; then
    fail "fire_once: a loop: false copy" "no top-level 'loop: true' to replace"
elif run once "$pfx" render "$work/fire_once.yaml" -o "$work/once" "${small[@]}" --frames "0:$n"; then
    a=$(frame "$work/once" fire_once "$n")
    b=$(frame "$work/once" fire_once 0)
    if [[ -f $a && -f $b ]] && ! cmp -s "$a" "$b"; then
        pass "fire_once (loop: false): frame $n differs from frame 0 (the byte check can fail)"
    else
        fail "fire_once (loop: false): frame $n differs from frame 0" "identical or missing"
    fi
    result=$(PYTHONPATH="$src/tests" "$py" "$work/seam.py" "$work/once" fire_once "$n" "$tolerance")
    status=$?
    read -r seam worst at <<<"$result"
    if [[ $status -eq 1 ]]; then
        pass "fire_once (loop: false): a visible seam: frames $((n - 1))->0 differ by $seam, above $tolerance x $worst (the seam check can fail)"
    elif [[ $status -eq 0 ]]; then
        fail "fire_once (loop: false): a visible seam" "frames $((n - 1))->0 differ by only $seam, within $tolerance x $worst"
    else
        fail "fire_once (loop: false): a visible seam" "the seam check could not read the frames"
    fi
else
    fail "fire_once: render --frames 0:$n" "pfx failed"
fi

summary
