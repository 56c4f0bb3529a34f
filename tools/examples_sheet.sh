#!/bin/bash
# Renders one frame of every example in effects/ at 256x256 and lays them
# out as docs/examples.png (the contact sheet the README shows), composited
# over a checkerboard so transparent backgrounds show as such. Each example
# is shown at 60 % of its duration unless FRAMES below names another frame
# (the one that shows what it is named: the flash of a muzzle flash or an
# impact, the fireball of the explosion). Frames are rendered with
# --alpha straight, which the compositing below assumes: an effect made in
# premultiplied alpha (muzzle_flash, impact) would otherwise lose its
# additive light (colour with zero alpha) on the checkerboard.
# Needs a built pfx and python3-pil.
#
# usage: tools/examples_sheet.sh [PFX] [OUT.png]
set -eu
src=$(cd "$(dirname "$0")/.." && pwd)
pfx=${1:-$src/build/pfx}
out=${2:-$src/docs/examples.png}
declare -A FRAMES=([particle_gun]=7 [sword_swipe]=5 [explosion]=13 [shockwave]=10 [genesis]=40
    [muzzle_flash]=1 [impact]=2)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cells=()
for effect in "$src"/effects/*.yaml; do
    name=$(basename "$effect" .yaml)
    duration=$(sed -n 's/^duration:[[:space:]]*\([0-9.]*\).*/\1/p' "$effect" | head -n 1)
    fps=$(sed -n 's/^fps:[[:space:]]*\([0-9.]*\).*/\1/p' "$effect" | head -n 1)
    frame=${FRAMES[$name]:-$(awk -v d="${duration:-2}" -v f="${fps:-30}" 'BEGIN { print int(d * f * 0.6) }')}
    "$pfx" render "$effect" -o "$work/$name" --frames "$frame:$frame" --size 256x256 --alpha straight -q
    cells+=("$name=$(printf '%s/%s/%s_%04d.png' "$work" "$name" "$name" "$frame")")
done
/usr/bin/python3 "$src/tools/contact_sheet.py" "$out" 256 4 "${cells[@]}"
