#!/usr/bin/env bash
# --set PATH=VALUE through the commands users run: render draws what the
# override says (a colour and a position give known pixels), overrides apply
# in order, a path through nothing is a located error with a suggestion
# (exit 1, nothing written), a value the format refuses is reported at the
# argument, validate and info see the override, manifests record it and it
# counts in the bake key, bake honours it, and a YAML alias keeps the file's
# value.
#
#   bash run_set.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" set "$@"
cd "$work" || exit 2

# One white 0.25 m square (a solid 8x8 texture) at the origin, seen by an
# orthographic camera 2 m high on 64x64 pixels: 32 pixels a metre, so the
# square covers 8x8 pixels around its centre, on opaque black.
"$py" -c 'from PIL import Image; Image.new("RGBA", (8, 8), (255,) * 4).save("white.png")'
cat >one.yaml <<'EOF'
pfx: 1
duration: 0.2
fps: 10
seed: 3
camera: { position: [0, 0, 5], target: [0, 0, 0], ortho: 2 }
image: { size: [64, 64], background: "#000000ff" }
emitters:
  one: &body
    bursts: [{ time: 0, count: 1 }]
    speed: 0
    lifetime: 10
    size: 0.25
    texture: white.png
    color: "#ffffffff"
    blend: alpha
    angle: 0   # a square, not turned at random
    forces: []
EOF

# pixels PNG X,Y...: the RGBA of each pixel, "r g b a" separated by ";".
pixels() {
    "$py" - "$@" <<'EOF'
import sys
from PIL import Image
im = Image.open(sys.argv[1]).convert("RGBA")
print(";".join(" ".join(map(str, im.getpixel(tuple(map(int, p.split(",")))))) for p in sys.argv[2:]))
EOF
}

# count PNG R G B: how many pixels have exactly that colour.
count() {
    "$py" - "$@" <<'EOF'
import sys
import numpy as np
from PIL import Image
a = np.asarray(Image.open(sys.argv[1]).convert("RGB")).reshape(-1, 3)
print(int((a == [int(v) for v in sys.argv[2:5]]).all(axis=1).sum()))
EOF
}

# setting MANIFEST: the manifest's "set" setting as JSON ("null" if none).
setting() {
    "$py" -c 'import json, sys; print(json.dumps(json.load(open(sys.argv[1]))["settings"].get("set")))' "$1"
}

begin "render without --set: the file's white square at the centre"
pfx_run render one.yaml -o plain -q
finished && want_status 0
[ "$(pixels plain/one_0000.png 32,32)" = "255 255 255 255" ] ||
    flunk "centre is $(pixels plain/one_0000.png 32,32), not white"
end

begin "render --set colour and position: a red 8x8 square at x = 0.5 m (pixel 48)"
pfx_run render one.yaml -o moved -q --set 'emitters.one.color=[1, 0, 0]' \
    --set 'emitters.one.position=[0.5, 0, 0]'
if finished; then
    want_status 0
    got=$(pixels moved/one_0000.png 48,32 32,32 44,28 51,35 43,32 52,32)
    [ "$got" = "255 0 0 255;0 0 0 255;255 0 0 255;255 0 0 255;0 0 0 255;0 0 0 255" ] ||
        flunk "pixels (48,32) (32,32) (44,28) (51,35) (43,32) (52,32): $got"
    n=$(count moved/one_0000.png 255 0 0)
    [ "$n" = 64 ] || flunk "$n red pixels, expected 8 x 8 = 64"
fi
end

begin "several --set apply in order: the last colour wins"
pfx_run render one.yaml -o order -q --set 'emitters.one.color=#00ff00' \
    --set 'emitters.one.color=#0000ff'
finished && want_status 0
[ "$(pixels order/one_0000.png 32,32)" = "0 0 255 255" ] ||
    flunk "centre is $(pixels order/one_0000.png 32,32), not blue"
end

begin "--set into a list item: color.1 of a gradient given by an earlier --set"
pfx_run render one.yaml -o item -q --set 'emitters.one.color=["#ff0000", "#ff0000"]' \
    --set 'emitters.one.color.0=#00ff00' --set 'emitters.one.color.1=#00ff00'
finished && want_status 0
[ "$(pixels item/one_0000.png 32,32)" = "0 255 0 255" ] ||
    flunk "centre is $(pixels item/one_0000.png 32,32), not green"
end

begin "a key the format lacks: the located error with the nearest path, exit 1, nothing written"
pfx_run render one.yaml -o typo --set emitters.one.colr=red
if finished; then
    want_status 1
    printf '%s\n' \
        "--set:1:14: error: 'emitters.one.colr' names no key of the effect format; did you mean 'emitters.one.color'? [PFX2001]" \
        "    1 | emitters.one.colr=red" \
        "      |              ^~~~" >typo.expected
    cmp -s typo.expected "$work/err" || flunk "stderr: $(diff typo.expected "$work/err")"
    [ ! -e typo ] || flunk "the output directory was created: $(ls -A typo)"
fi
end

begin "an emitter the file lacks: the located error naming the file, with the nearest name"
pfx_run render one.yaml -o name --set emitters.on.color=red
if finished; then
    want_status 1
    stderr_has "--set:1:10: error: 'emitters.on' names nothing in 'one.yaml'; did you mean 'emitters.one'? [PFX4001]"
    [ ! -e name ] || flunk "the output directory was created"
fi
end

begin "the second of two --set is the line 2 of --set; a list index past the end"
pfx_run validate one.yaml --set emitters.one.size=1 --set emitters.one.bursts.1.count=3
if finished; then
    want_status 1
    stderr_has "--set:2:21: error: 'emitters.one.bursts.1' names nothing in 'one.yaml': 'emitters.one.bursts' is a list of 1, indexed from 0 [PFX4001]"
    stderr_has "    2 | emitters.one.bursts.1.count=3"
fi
end

begin "a value the format refuses: reported at the --set, naming the file's value it replaced"
pfx_run render one.yaml -o refused --set emitters.one.size=-1
if finished; then
    want_status 1
    stderr_has "--set:1:19: error: 'size' must be at least 0, got -1 [PFX3001]"
    stderr_has "--set:1:1: note: 'emitters.one.size' replaces the value at one.yaml:12:11"
    [ ! -e refused ] || flunk "the output directory was created"
fi
end

begin "a malformed VALUE is a YAML error at its column"
pfx_run validate one.yaml --set 'emitters.one.size=[1,'
finished && want_status 1
stderr_has "--set:1:19: error: did not find expected node content [PFX1001]"
end

begin "validate honours --set: a broken file passes when --set mends it, fails when it breaks"
sed 's/lifetime: 10/lifetime: 0/' one.yaml >broken.yaml
pfx_run validate broken.yaml
finished && want_status 1
pfx_run validate broken.yaml --set emitters.one.lifetime=2 -q
finished && want_status 0 && stderr_empty
pfx_run validate one.yaml --set emitters.one.lifetime=0
finished && want_status 1
stderr_has "--set:1:23: error: 'lifetime' must be greater than 0, got 0 [PFX3001]"
end

begin "validate --format json: the --set diagnostic names the file --set"
pfx_run validate --format json one.yaml --set camera.fovv=30
finished && want_status 1
stderr_has '{"file":"--set","line":1,"column":8,"severity":"error","rule":"PFX2001"'
end

begin "info honours --set, and adds a key the file lacks (sim.rate, no sim in the file)"
pfx_run info one.yaml --set 'image.size=[32, 16]' --set sim.rate=60
if finished; then
    want_status 0
    stdout_has "image 32x16"
    stdout_has "simulation 60 steps/s"
fi
pfx_run info one.yaml --set fps=60 --fps 30
finished && want_status 0
stdout_has "frames 6 (0.2 s at 30 fps)" # --fps wins over --set fps
pfx_run info one.yaml --format json --set 'image.size=[32, 16]'
finished && want_status 0
[ "$("$py" -c 'import json,sys; d=json.load(open(sys.argv[1])); print(d["width"], d["height"])' "$work/out")" = "32 16" ] ||
    flunk "info --format json does not say 32 x 16"
end

begin "the manifest records --set; another value is not up to date and re-renders"
pfx_run render one.yaml -o man --set 'emitters.one.color=#ff0000'
finished && want_status 0
[ "$(setting man/one.manifest.json)" = '["emitters.one.color=#ff0000"]' ] ||
    flunk "manifest set: $(setting man/one.manifest.json)"
pfx_run render one.yaml -o man --set 'emitters.one.color=#ff0000'
finished && want_status 0
stderr_has "is up to date in 'man'"
pfx_run render one.yaml -o man --set 'emitters.one.color=#00ff00'
finished && want_status 0
stderr_has "pfx: rendered 'one.yaml'"
[ "$(pixels man/one_0000.png 32,32)" = "0 255 0 255" ] || flunk "not re-rendered green"
[ "$(setting man/one.manifest.json)" = '["emitters.one.color=#00ff00"]' ] ||
    flunk "manifest set: $(setting man/one.manifest.json)"
pfx_run render one.yaml -o man
finished && want_status 0
stderr_has "pfx: rendered 'one.yaml'"
[ "$(setting man/one.manifest.json)" = null ] || flunk "a render without --set still records one"
[ "$(pixels man/one_0000.png 32,32)" = "255 255 255 255" ] || flunk "not re-rendered white"
end

begin "bake honours --set, records it, and another value bakes again"
pfx_run bake one.yaml -o bake.csv --set 'emitters.one.position=[0.5, 0, 0]'
finished && want_status 0
# frame,time,emitter,id,x,...: x of the one particle in frame 0
[ "$(awk -F, '$1 == 0 { print $3, $5 }' bake.csv)" = "one 0.5" ] ||
    flunk "frame 0: $(awk -F, '$1 == 0' bake.csv)"
[ "$(setting bake.csv.manifest.json)" = '["emitters.one.position=[0.5, 0, 0]"]' ] ||
    flunk "manifest set: $(setting bake.csv.manifest.json)"
pfx_run bake one.yaml -o bake.csv --set 'emitters.one.position=[0.25, 0, 0]'
finished && want_status 0
stderr_has "pfx: baked"
[ "$(awk -F, '$1 == 0 { print $5 }' bake.csv)" = "0.25" ] || flunk "not baked again at 0.25"
end

begin "a YAML alias keeps the file's value: only the emitter named moves"
{ cat one.yaml; echo "  two: *body"; } >alias.yaml
pfx_run bake alias.yaml -o alias.csv --set emitters.two.size=0.5
finished && want_status 0
# frame,time,emitter,id,x,y,z,vx,vy,vz,age,lifetime,size,...
[ "$(awk -F, '$1 == 0 { print $3, $13 }' alias.csv | tr '\n' ' ')" = "one 0.25 two 0.5 " ] ||
    flunk "frame 0: $(awk -F, '$1 == 0' alias.csv | tr '\n' ' ')"
end

begin "usage errors: no '=', and a command that reads no effect"
pfx_run info one.yaml --set emitters.one.size
finished && want_status 2
stderr_has "pfx: --set takes PATH=VALUE, such as emitters.flame.rate=300, got 'emitters.one.size'"
pfx_run schema --set a=1
finished && want_status 2
end

summary
