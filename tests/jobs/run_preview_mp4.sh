#!/usr/bin/env bash
# --preview out.mp4: pfx pipes the frames to the ffmpeg on the PATH. Read
# back by ffprobe (codec, pixel format, padded even size, frame rate,
# frames counted by decoding) and decoded by ffmpeg to raw RGB, where known
# colours must show within the lossy codec's tolerance: the effect's
# background in a corner, the white sprite at the centre, and black where
# the background is transparent (pfx composites over black). Then the
# failures: no ffmpeg on the PATH (refused before rendering), fake
# ffmpegs that fail or die (status and last words reported, no file left)
# or hang while pfx gets SIGTERM (no temporary left), and pfx started with
# its standard streams closed.
#
#   bash run_preview_mp4.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" preview_mp4 "$@"
cd "$work" || exit 2

# One white square sprite at the origin, which the camera looks at, over
# #2060a0, 63x47 pixels (odd both ways: the MP4 is padded to 64x48), 10
# frames at 20 fps.
effect() {
    cat <<EOF
pfx: 1
duration: 0.5
fps: 20
seed: 1
camera: { position: [0, 0, 5], target: [0, 0, 0], fov: 40 }
image: { size: [63, 47], background: "$1" }
emitters:
  dot:
    shape: { type: point }
    rate: 0
    bursts: [{ time: 0, count: 1 }]
    speed: 0
    lifetime: 10
    size: 2.5
    color: "#ffffff"
    sprite: square
    blend: alpha
EOF
}
effect '#2060a0' >dot.yaml
effect transparent >clear.yaml

if ! command -v ffmpeg >/dev/null || ! command -v ffprobe >/dev/null; then
    fail "ffmpeg and ffprobe" "missing (Debian's ffmpeg; ./install-deps --test)"
    summary
    exit
fi

begin "render --preview d/dot.mp4"
pfx_run render dot.yaml -o d --preview d/dot.mp4
want_status 0
stderr_has "preview 'd/dot.mp4'"
[ -s d/dot.mp4 ] || flunk "no d/dot.mp4"
ls -a d | grep -q '\.tmp-' && flunk "a temporary is left: $(ls -a d)"
end

# probe MP4: ffprobe's view, decoding every frame to count them.
probe() {
    ffprobe -v error -select_streams v:0 -count_frames \
        -show_entries stream=codec_name,pix_fmt,width,height,r_frame_rate,nb_read_frames \
        -of json "$1"
}
begin "ffprobe: h264, yuv420p, 64x48, 20 fps, 10 frames"
probe d/dot.mp4 >probe.json 2>probe.err || flunk "ffprobe rejects it: $(tail -2 probe.err)"
got=$("$py" -c 'import json,sys; s=json.load(open(sys.argv[1]))["streams"][0]
print(s["codec_name"], s["pix_fmt"], s["width"], s["height"], s["r_frame_rate"], s["nb_read_frames"])' probe.json)
[ "$got" = "h264 yuv420p 64 48 20/1 10" ] || flunk "got '$got'"
end

# frame MP4 N OUT: frame N of MP4 as raw rgb24.
frame() { ffmpeg -v error -nostdin -i "$1" -vf "select=eq(n\\,$2)" -frames:v 1 -f rawvideo -pix_fmt rgb24 -y "$3"; }
# colours RAW: checks known colours in a 64x48 rgb24 frame: the 4x4 block
# in the top left corner near BG (r,g,b), the 3x3 block at the centre
# near white. Tolerance 12 of 255: H.264 at crf 18 and the YUV round trip.
colours() {
    "$py" - "$@" <<'PY'
import sys
import numpy as np
raw, bg = sys.argv[1], [int(v) for v in sys.argv[2].split(",")]
b = np.fromfile(raw, np.uint8)
if b.size != 64 * 48 * 3:
    print("FAIL %s: %d bytes, not a 64x48 RGB frame" % (raw, b.size)); sys.exit()
b = b.reshape(48, 64, 3).astype(int)
corner = b[1:5, 1:5].reshape(-1, 3).mean(axis=0)
centre = b[22:25, 30:33].reshape(-1, 3).mean(axis=0)
bad = []
if np.abs(corner - bg).max() > 12:
    bad.append("corner %s, expected %s" % (corner.round().astype(int).tolist(), bg))
if centre.min() < 255 - 12:
    bad.append("centre %s, expected white" % centre.round().astype(int).tolist())
print(("FAIL %s: " % raw + "; ".join(bad)) if bad else "ok   %s: corner %s, centre white" % (raw, bg))
PY
}
frame d/dot.mp4 3 dot3.rgb 2>frame.err || fail "ffmpeg decodes frame 3" "$(tail -2 frame.err)"
tally "$(colours dot3.rgb 32,96,160)"

begin "the manifest names the preview in its settings, as for WebP"
got=$("$py" -c 'import json,sys; print(json.load(open(sys.argv[1]))["settings"].get("preview"))' d/dot.manifest.json)
[ "$got" = d/dot.mp4 ] || flunk "preview is '$got'"
end

begin "a transparent background: composited over black"
pfx_run render clear.yaml -o c --preview c/clear.mp4
want_status 0
frame c/clear.mp4 3 clear3.rgb 2>frame.err || flunk "ffmpeg cannot decode it: $(tail -2 frame.err)"
end
tally "$(colours clear3.rgb 0,0,0)"

begin "assemble --preview out.mp4 from two slices"
pfx_run render dot.yaml -o s -q --slice 0/2
pfx_run render dot.yaml -o s -q --slice 1/2
pfx_run assemble s -o a --preview a/dot.mp4
want_status 0
got=$(probe a/dot.mp4 2>&1 | "$py" -c 'import json,sys; print(json.load(sys.stdin)["streams"][0]["nb_read_frames"])')
[ "$got" = 10 ] || flunk "$got frames"
end

# --preview without ffmpeg: PATH names a directory without one (pfx is
# started by its absolute path). Nothing may be rendered.
mkdir -p empty
begin "no ffmpeg on the PATH: one line, exit 1, nothing rendered"
PATH=$work/empty "$pfx" render dot.yaml -o n --preview n/dot.mp4 >"$work/out" 2>"$work/err"
status=$?
want_status 1
[ "$(cat err)" = "pfx: cannot write 'n/dot.mp4': ffmpeg not found on PATH (install ffmpeg or use --preview n/dot.webp) [PFX9009]" ] ||
    flunk "stderr: $(cat err)"
[ -e n ] && flunk "n was created: $(ls -a n)"
end

# A fake ffmpeg that fails at once: its status and last lines reported,
# no MP4 and no temporary left, and pfx not killed by SIGPIPE.
mkdir -p fake
cat >fake/ffmpeg <<'EOF'
#!/bin/sh
echo "a line too early to be shown" >&2
echo "fake ffmpeg: Input #0, rawvideo" >&2
echo "fake ffmpeg: first of its last words" >&2
echo "Unknown encoder 'libx264'" >&2
exit 3
EOF
chmod +x fake/ffmpeg
begin "a failing ffmpeg: its status and stderr, no file left"
PATH=$work/fake:$PATH pfx_run render dot.yaml -o e --preview e/dot.mp4
finished && want_status 1
stderr_has "pfx: cannot write 'e/dot.mp4': ffmpeg exited with status 3: fake ffmpeg: Input #0, rawvideo; fake ffmpeg: first of its last words; Unknown encoder 'libx264'"
grep -q "too early" err && flunk "more than the last three lines: $(cat err)"
[ -e e/dot.mp4 ] && flunk "e/dot.mp4 was left"
ls -a e | grep -q '\.tmp-' && flunk "a temporary is left: $(ls -a e)"
end

# One that reads every frame and then dies of a signal.
cat >fake/ffmpeg <<'EOF'
#!/bin/sh
cat >/dev/null
kill -KILL $$
EOF
begin "an ffmpeg killed by a signal"
PATH=$work/fake:$PATH pfx_run render dot.yaml -o k --preview k/dot.mp4
finished && want_status 1
stderr_has "pfx: cannot write 'k/dot.mp4': ffmpeg was killed by signal 9"
[ -e k/dot.mp4 ] && flunk "k/dot.mp4 was left"
end

# One that writes a little to the file pfx gave it and then hangs: pfx
# blocks on the full pipe, and SIGTERM must still remove the temporary
# (ffmpeg writes only through the descriptor, so nothing comes back).
cat >fake/ffmpeg <<EOF
#!/bin/sh
echo \$\$ >"$work/fake.pid"
echo partial >&3
exec sleep 20
EOF
begin "SIGTERM while ffmpeg writes: exit 143, no temporary"
got=$(PATH=$work/fake:$PATH "$py" - "$pfx" <<'PY'
import os, signal, subprocess, sys, time
p = subprocess.Popen([sys.argv[1], "render", "dot.yaml", "-o", "t", "--preview", "t/dot.mp4", "-q"])
def partial():
    return os.path.isdir("t") and any(".tmp-" in f and f.startswith(".dot.mp4") and
                                      os.path.getsize("t/" + f) > 0 for f in os.listdir("t"))
end = time.time() + 60
while time.time() < end and p.poll() is None and not partial():
    time.sleep(0.01)
p.send_signal(signal.SIGTERM)
try:
    print(p.wait(10))
except subprocess.TimeoutExpired:
    p.kill()
    print("hung")
PY
)
[ "$got" = -15 ] || flunk "ended with '$got', not by SIGTERM"
ls -a t | grep -q '\.tmp-' && flunk "a temporary is left: $(ls -a t)"
[ -e t/dot.mp4 ] && flunk "t/dot.mp4 was left"
end
[ -s fake.pid ] && kill "$(cat fake.pid)" 2>/dev/null

begin "standard streams closed: ffmpeg still gets its pipe, log and file"
"$pfx" render dot.yaml -o z --preview z/dot.mp4 <&- >&- 2>/dev/null
status=$?
want_status 0
got=$(probe z/dot.mp4 2>&1 | "$py" -c 'import json,sys; print(json.load(sys.stdin)["streams"][0]["nb_read_frames"])')
[ "$got" = 10 ] || flunk "$got frames"
end

# light FRAMES-GLOB MP4 W H: the MP4 decoded by ffmpeg against the PNG
# frames (premultiplied) composited over black, which is their RGB as it
# is: the mean light within 4%, and each pixel within 24 of 255 on average
# within 3 (H.264 at CRF 18 with 4:2:0 chroma blurs colour edges).
light() {
    ffmpeg -v error -nostdin -i "$2" -f rawvideo -pix_fmt rgb24 -y decoded.rgb 2>frame.err ||
        { echo "FAIL ffmpeg cannot decode $2: $(tail -2 frame.err)"; return; }
    "$py" - "$@" <<'PY'
import glob, sys
from PIL import Image
import numpy as np
pattern, mp4, w, h = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
want = np.stack([np.asarray(Image.open(f).convert("RGBA")).astype(float)[..., :3]
                 for f in sorted(glob.glob(pattern))])
got = np.fromfile("decoded.rgb", np.uint8).astype(float)
if got.size != want.size:
    print("FAIL %s: %d bytes decoded, %d expected" % (mp4, got.size, want.size)); sys.exit()
got = got.reshape(want.shape)
diff = np.abs(got - want).mean()
ok = abs(got.mean() - want.mean()) <= 0.04 * want.mean() and diff <= 3
print("%s %s: mean light %.2f against %.2f in the frames, mean difference %.2f"
      % ("ok  " if ok else "FAIL", mp4, got.mean(), want.mean(), diff))
PY
}

# The explosion on a transparent background: alpha-blended smoke and
# additive fire, whose light has alpha 0.
sed '/^  background:/d' "$src/effects/explosion.yaml" >boom.yaml
ln -s "$src/effects/textures" textures
begin "a premultiplied render: the MP4 shows the frames' light over black"
pfx_run render boom.yaml -o pm --size 64x48 --frames 0:29 --alpha premultiplied --preview pm/boom.mp4
want_status 0
end
tally "$(light 'pm/boom_00*.png' pm/boom.mp4 64 48)"

begin "--preview-quality 30: a smaller MP4 (CRF 36) close to the default"
pfx_run render boom.yaml -o pq --size 64x48 --frames 0:29 --alpha premultiplied \
    --preview pq/boom.mp4 --preview-quality 30
want_status 0
a=$(stat -c %s pm/boom.mp4) b=$(stat -c %s pq/boom.mp4)
[ "$b" -lt "$a" ] || flunk "$b bytes, not fewer than the default's $a"
ffmpeg -v error -nostdin -i pq/boom.mp4 -f rawvideo -pix_fmt rgb24 -y q.rgb &&
    ffmpeg -v error -nostdin -i pm/boom.mp4 -f rawvideo -pix_fmt rgb24 -y d.rgb ||
    flunk "ffmpeg cannot decode them"
"$py" -c 'import numpy as np; a=np.fromfile("q.rgb",np.uint8).astype(float); b=np.fromfile("d.rgb",np.uint8).astype(float); import sys; sys.exit(not (a.size==b.size and np.abs(a-b).mean() < 4))' ||
    flunk "it decodes far from the default"
end

# A file size limit the frames fit under and the MP4 does not: ffmpeg 5.1
# then exits 0 after "Error writing trailer", leaving no index (moov).
begin "an MP4 cut short by a file size limit: exit 1, no MP4, then made again"
(ulimit -f 20 && exec "$pfx" render "$src/effects/fire.yaml" -o lim --size 128x128 -q \
    --preview lim/fire.mp4) >out 2>err
status=$?
want_status 1
grep -q "cannot write 'lim/fire.mp4': ffmpeg exited 0 but its MP4 is incomplete (it has no 'moov' box)" err ||
    flunk "stderr: $(cat err)"
[ -e lim/fire.mp4 ] && flunk "lim/fire.mp4 was left"
ls -a lim | grep -q '\.tmp-' && flunk "a temporary is left: $(ls -a lim)"
"$pfx" render "$src/effects/fire.yaml" -o lim --size 128x128 -q --preview lim/fire.mp4 2>err ||
    flunk "the run without the limit failed: $(cat err)"
ffprobe -v error lim/fire.mp4 || flunk "ffprobe rejects the MP4 made without the limit"
end

begin "--preview refuses other extensions"
pfx_run render dot.yaml -o g --preview g/dot.gif
want_status 2
stderr_has "give a path ending in '.webp' or '.mp4', got 'g/dot.gif'"
end

summary
