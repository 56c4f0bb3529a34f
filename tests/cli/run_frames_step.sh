#!/usr/bin/env bash
# --frames A:B:S: every S-th frame from A, numbered as in a full render.
# render --frames 0:20:5 writes exactly frames 0, 5, 10, 15 and 20, each
# byte-identical to that frame of a full 0:20 render, with -j and with
# slices as well; Pillow reads them as the full render's images. A range
# ends where the step lands (0:22:5 is the same five frames, and up to date
# after 0:20:5), the manifest records the step (so a render of another
# step is not up to date), and bake takes it as it takes --every.
#
#   bash run_frames_step.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" frames_step "$@"
cd "$src" || exit 2
FIRE=effects/fire.yaml
SMALL=(--size 64x64 -q)

# names DIR: the PNG names in DIR, on one line.
names() { (cd "$1" && ls -- *.png 2>/dev/null | tr '\n' ' '); }
want_names="fire_0000.png fire_0005.png fire_0010.png fire_0015.png fire_0020.png "

# same_as_full DIR: every PNG in DIR equals the full render's, byte for byte.
same_as_full() {
    local f
    for f in "$1"/*.png; do
        cmp -s "$f" "$work/full/${f##*/}" || flunk "${f#"$work"/} differs from the full render's"
    done
}

run full "$pfx" render "$FIRE" -o "$work/full" --frames 0:20 "${SMALL[@]}" ||
    fail "the full render"

begin "render --frames 0:20:5: frames 0, 5, 10, 15, 20, the full render's bytes"
pfx_run render "$FIRE" -o "$work/step" --frames 0:20:5 --size 64x64
if finished; then
    want_status 0
    [ "$(names "$work/step")" = "$want_names" ] || flunk "wrote $(names "$work/step")"
    same_as_full "$work/step"
    stderr_has "5 frames (0 to 20, every 5)"
fi
end

# Read back with Pillow: the same image as the full render's frame, and not
# the same as its neighbour (so the numbering is not off by one).
# A sheet and a preview of a stepped render hold the stepped frames, and
# play at fps / S so that they last as long as the effect.
begin "--atlas and --preview of --frames 0:20:5: five cells, five frames, at fps / 5"
pfx_run render "$FIRE" -o "$work/sheet" --frames 0:20:5 --size 64x64 --atlas=5x1 --padding 0 \
    --extrude 0 --preview "$work/sheet/fire.webp"
if finished; then
    want_status 0
    out=$("$py" - "$work" "$(sed -n 's/^fps: *//p' "$FIRE")" <<'PY'
import json, sys
from PIL import Image, ImageChops
d, fps = sys.argv[1], float(sys.argv[2] or 30)
sheet = Image.open("%s/sheet/fire_atlas.png" % d).convert("RGBA")
meta = json.load(open("%s/sheet/fire_atlas.json" % d))
if sheet.size != (320, 64):
    print("the sheet is %s, not 320x64" % (sheet.size,))
if abs(meta["meta"]["grid"]["fps"] - fps / 5) > 1e-9:
    print("the sheet's fps is %s, not %s" % (meta["meta"]["grid"]["fps"], fps / 5))
if sorted(meta["frames"]) != ["fire_%04d.png" % f for f in (0, 5, 10, 15, 20)]:
    print("the sheet names %s" % sorted(meta["frames"]))
web = Image.open("%s/sheet/fire.webp" % d)
if web.n_frames != 5:
    print("the preview has %d frames" % web.n_frames)
for k, f in enumerate((0, 5, 10, 15, 20)):
    full = Image.open("%s/full/fire_%04d.png" % (d, f)).convert("RGBA")
    cell = sheet.crop((64 * k, 0, 64 * k + 64, 64))
    if ImageChops.difference(cell, full).getbbox() is not None:
        print("cell %d is not frame %d" % (k, f))
    web.seek(k)
    if abs(web.info["duration"] - 5000 / fps) > 1:
        print("preview frame %d lasts %s ms, not %.0f" % (k, web.info["duration"], 5000 / fps))
PY
)
    [ -z "$out" ] || flunk "$out"
fi
end

begin "Pillow reads each stepped frame as the full render's frame of that number"
out=$("$py" - "$work" <<'PY'
import sys
from PIL import Image, ImageChops
d = sys.argv[1]
for f in (0, 5, 10, 15, 20):
    a = Image.open("%s/step/fire_%04d.png" % (d, f)).convert("RGBA")
    b = Image.open("%s/full/fire_%04d.png" % (d, f)).convert("RGBA")
    if a.size != (64, 64) or ImageChops.difference(a, b).getbbox() is not None:
        print("frame %d: size %s, differs from the full render's" % (f, a.size))
    if f:
        c = Image.open("%s/full/fire_%04d.png" % (d, f - 1)).convert("RGBA")
        if ImageChops.difference(a, c).getbbox() is None:
            print("frame %d equals frame %d" % (f, f - 1))
PY
)
[ -z "$out" ] || flunk "$out"
end

begin "-j 3 with a step: the same names and bytes"
pfx_run render "$FIRE" -o "$work/j3" --frames 0:20:5 -j 3 "${SMALL[@]}"
want_status 0
[ "$(names "$work/j3")" = "$want_names" ] || flunk "wrote $(names "$work/j3")"
same_as_full "$work/j3"
end

begin "--slice I/3 with a step: each frame once over the slices, the same bytes"
for i in 0 1 2; do
    pfx_run render "$FIRE" -o "$work/sliced" --frames 0:20:5 --slice "$i/3" "${SMALL[@]}"
    want_status 0
done
[ "$(names "$work/sliced")" = "$want_names" ] || flunk "wrote $(names "$work/sliced")"
same_as_full "$work/sliced"
n=$(cat "$work"/sliced/fire.slice-*.manifest.json | grep -c '"fire_00[0-9][0-9].png"')
[ "$n" = 5 ] || flunk "the slices' manifests list $n frames, not 5"
end

begin "0:22:5 is 0:20:5: up to date; another step is not"
pfx_run render "$FIRE" -o "$work/step" --frames 0:22:5 --size 64x64
want_status 0
stderr_has "is up to date"
"$py" -c 'import json,sys; s=json.load(open(sys.argv[1]))["settings"]; sys.exit(not (s["frames"]==[0,20] and s["step"]==5))' \
    "$work/step/fire.manifest.json" || flunk "the manifest lacks frames [0, 20] and step 5"
pfx_run render "$FIRE" -o "$work/step" --frames 0:20:10 --size 64x64
want_status 0
stderr_has "3 frames (0 to 20, every 10)"
[ "$(names "$work/step")" = "fire_0000.png fire_0010.png fire_0020.png " ] ||
    flunk "after 0:20:10: $(names "$work/step")"
end

# Only the frames a step writes are checked against the inputs: a texture
# named like a frame the step skips (m_0001.png under 0:2:2) is left alone
# and read, while 0:2 would write over it and is refused before any work.
mkdir -p "$work/tx/out"
"$py" -c "from PIL import Image; Image.new('RGBA', (8, 8), (255,) * 4).save('$work/tx/out/m_0001.png')"
cat >"$work/tx/m.yaml" <<'YAML'
pfx: 1
duration: 0.3
fps: 10
camera: { position: [0, 0, 5], target: [0, 0, 0], ortho: 2 }
image: { size: [32, 32] }
emitters:
  one: { rate: 20, lifetime: 1, size: 0.3, texture: out/m_0001.png }
YAML
begin "a step checks only the frames it writes against the inputs"
h=$(sha256sum "$work/tx/out/m_0001.png" | cut -d' ' -f1)
pfx_run render "$work/tx/m.yaml" -o "$work/tx/out" --frames 0:2 -q
want_status 1
stderr_has "cannot write '$work/tx/out/m_0001.png': it is the input"
pfx_run render "$work/tx/m.yaml" -o "$work/tx/out" --frames 0:2:2 -q
want_status 0
[ "$(names "$work/tx/out")" = "m_0000.png m_0001.png m_0002.png " ] || flunk "wrote $(names "$work/tx/out")"
[ "$(sha256sum "$work/tx/out/m_0001.png" | cut -d' ' -f1)" = "$h" ] || flunk "the texture changed"
end

begin "A::S: every S-th frame from A to the end"
pfx_run render "$FIRE" -o "$work/tail" --frames 100::10 "${SMALL[@]}"
want_status 0
n=$("$pfx" info "$FIRE" --format json | "$py" -c 'import json,sys; print(json.load(sys.stdin)["frames"])')
want=""
for ((f = 100; f < n; f += 10)); do want+="$(printf 'fire_%04d.png ' "$f")"; done
[ -n "$want" ] && [ "$(names "$work/tail")" = "$want" ] || flunk "wrote $(names "$work/tail"), want $want"
end

begin "bake --frames 0:20:5: the frames 0, 5, ..., 20, as --every 5 bakes them"
pfx_run bake "$FIRE" -o "$work/step.csv" --frames 0:20:5
want_status 0
stderr_has "frames 0 to 20, every 5"
pfx_run bake "$FIRE" -o "$work/every.csv" --frames 0:20 --every 5 -q
want_status 0
cmp -s "$work/step.csv" "$work/every.csv" || flunk "the bakes differ"
[ "$(tail -n +2 "$work/step.csv" | cut -d, -f1 | uniq | tr '\n' ' ')" = "0 5 10 15 20 " ] ||
    flunk "frames $(tail -n +2 "$work/step.csv" | cut -d, -f1 | uniq | tr '\n' ' ')"
end

# usage_error NAME MESSAGE ARGS...
usage_error() {
    begin "$1"
    local msg=$2
    shift 2
    pfx_run "$@"
    want_status 2
    stdout_empty
    stderr_has "pfx: $msg"
    end
}
usage_error "a step of 0" "--frames takes N, A:B or A: (to the end), then :S" render "$FIRE" \
    -o "$work/u" --frames 0:20:0
usage_error "a step that is not a number" "--frames takes" render "$FIRE" -o "$work/u" \
    --frames 0:20:x
usage_error "--every and a step that disagree" "--every N and --frames A:B:S" bake "$FIRE" \
    -o "$work/u.csv" --frames 0:20:5 --every 2
usage_error "--every for render" "--every is for bake; other commands take every S-th frame" \
    render "$FIRE" -o "$work/u" --frames 0:20 --every 5
usage_error "--motion-vectors with a step" "--motion-vectors cannot go with a --frames step" \
    render "$FIRE" -o "$work/u" --frames 0:20:5 --motion-vectors
begin "the usage errors wrote nothing"
[ ! -e "$work/u" ] && [ ! -e "$work/u.csv" ] || flunk "output left behind"
end

summary
