#!/usr/bin/env bash
# light: { shadows: true } with no lit sprite emitter darkens nothing (the
# compiler warns so): no frame builds or uploads the opacity volume, so
# `pfx info` counts none of its memory (the driver's part is the same as
# without shadows, where it was 1.5 MiB more), and the frames are the same
# pixels as without the light's shadows.
#
#   bash run_unlit_shadows.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" unlit_shadows "$@"
cd "$work" || exit 2

# effect FILE SHADOWS LIT: a smoke-like puff, alpha-blended (a caster).
effect() {
    cat >"$1" <<YAML
pfx: 1
duration: 0.3
fps: 10
seed: 4
sim: { prewarm: 0.5 }
image: { size: [64, 64] }
camera: { position: [0, 0, 4], target: [0, 0, 0], fov: 40 }
light: { direction: [0, -1, 0], shadows: $2 }
emitters:
  puff:
    shape: { type: sphere, radius: 0.4 }
    rate: 200
    lifetime: 1
    speed: 0.1
    size: 0.5
    color: "#8090a0c0"
    blend: alpha
    lit: $3
YAML
}
effect shadowed.yaml true false
effect plain.yaml false false
effect lit.yaml true true

# driver_bytes FILE: memory.parts.driver of pfx info --format json.
driver_bytes() {
    "$pfx" info --format json "$1" 2>/dev/null |
        "$py" -c 'import json, sys; print(int(json.load(sys.stdin)["memory"]["parts"]["driver"]))'
}

begin "shadows with no lit emitter: no volume in the memory estimate"
a=$(driver_bytes shadowed.yaml) b=$(driver_bytes plain.yaml) c=$(driver_bytes lit.yaml)
[[ -n $a && -n $b && -n $c ]] || flunk "pfx info failed"
[[ $a == "$b" ]] || flunk "driver bytes $a with unlit shadows, $b without shadows"
# A lit emitter does read it: three volumes of 64 x 64 x 32 floats more.
((c - b >= 3 * 64 * 64 * 32 * 4)) || flunk "lit: $c, unlit: $b"
end

begin "shadows with no lit emitter: the same pixels as without"
"$pfx" render shadowed.yaml -o s -q 2>/dev/null && "$pfx" render plain.yaml -o p -q ||
    flunk "pfx render failed"
"$py" - s p <<'PY' || flunk "the frames differ"
import glob, os, sys
from PIL import Image
a = sorted(glob.glob(sys.argv[1] + "/*.png"))
assert len(a) == 3, a
for f in a:
    x = Image.open(f).convert("RGBA")
    y = Image.open(sys.argv[2] + "/" + os.path.basename(f).replace("shadowed", "plain")).convert("RGBA")
    assert list(x.getdata()) == list(y.getdata()), f
    assert x.getextrema()[3][1] > 0, f  # something was drawn
PY
end

summary
