#!/usr/bin/env bash
# Slice folders are input, not trust: `pfx assemble` must refuse crafted
# slice manifests (names that leave OUT, FIFOs, links to /dev/zero, frames
# whose header claims a huge size, bad fps) with a clear error, write
# nothing outside OUT, never hang, and stay linear in the outputs. Render's
# own manifest checks (listed and stale outputs, previews) share the paths.
#
#   bash run_assemble_input.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" assemble_input "$@"
cd "$work" || exit 2
FIRE=$src/effects/fire.yaml
A=(--size 48x48 --frames 0:5 --seed 3 -q)
pfx_timeout=30
M0=fire.slice-0000-of-0002.manifest.json
M1=fire.slice-0001-of-0002.manifest.json

for i in 0 1; do
    "$pfx" render "$FIRE" -o s$i "${A[@]}" --slice $i/2 || exit 2
done

# edit DIR SCRIPT: runs the Python SCRIPT on DIR's slice manifest as m.
edit() {
    "$py" - "$1"/fire.slice-*.manifest.json "$2" <<'PY'
import hashlib, json, sys
path, code = sys.argv[1], sys.argv[2]
m = json.load(open(path))
def sha(p): return hashlib.sha256(open(p, "rb").read()).hexdigest()
exec(code)
json.dump(m, open(path, "w"))
PY
}

# Names that are not plain file names in the slice's folder: each refused
# with the manifest and the name in the message, nothing written anywhere.
n=0
for name in '../evil.sh' '../../evil.sh' "$work/abs-evil.sh" 'sub/evil.sh' '.' '..' '.hidden' \
    $'bad\x1b[2Jname' 'a\\b' ''; do
    n=$((n + 1))
    begin "a listed output named '$(printf '%q' "$name")' is refused"
    rm -rf t && mkdir -p t/o && cp -r s0 s1 t/
    printf 'echo owned\n' >t/evil.sh
    NAME=$name edit t/s1 "import os; m['outputs'].append({'path': os.environ['NAME'], 'sha256': sha('t/evil.sh')})"
    pfx_run assemble t/s0 t/s1 -o t/o/all
    finished && want_status 1
    stderr_has "t/s1/$M1' lists the output '"
    stderr_has "which is not a plain file name in its directory"
    grep -q $'\x1b' "$work/err" && flunk "a control byte reached stderr"
    [ ! -e t/o/evil.sh ] && [ ! -e t/o/all/sub ] && [ ! -e "$work/abs-evil.sh" ] || flunk "a file was written outside OUT"
    [ ! -e t/o/all/fire.manifest.json ] || flunk "a manifest was written"
    end
done

begin "an output without its SHA-256 is refused"
rm -rf t && mkdir t && cp -r s0 s1 t/
edit t/s1 "m['outputs'][0]['sha256'] = 'x' * 64"
pfx_run assemble t/s0 t/s1 -o t/all
finished && want_status 1
stderr_has "records no SHA-256 for the output 'fire_0003.png'"
end

# Files that are not regular: a FIFO (no writer: open would block) and a
# link to /dev/zero (endless), as a slice's frame, as a listed output of a
# previous render and as its stale output. Each an error or skipped, in
# bounded time.
for kind in fifo zero; do
    make_bad() {
        rm -f "$1"
        if [ $kind = fifo ]; then mkfifo "$1"; else ln -s /dev/zero "$1"; fi
    }
    begin "a slice frame that is a $kind: an error, no hang"
    rm -rf t && mkdir t && cp -r s0 s1 t/
    make_bad t/s1/fire_0004.png
    pfx_run assemble t/s0 t/s1 -o t/all
    finished && want_status 1
    stderr_has "cannot read 't/s1/fire_0004.png': not a regular file"
    [ ! -e t/all/fire.manifest.json ] || flunk "a manifest was written"
    end

    begin "a frame in OUT that is a $kind: replaced by assemble, no hang"
    rm -rf t && mkdir -p t/all && cp -r s0 s1 t/
    make_bad t/all/fire_0001.png
    pfx_run assemble t/s0 t/s1 -o t/all
    finished && want_status 0
    [ -f t/all/fire_0001.png ] && [ ! -L t/all/fire_0001.png ] && cmp -s t/all/fire_0001.png s0/fire_0001.png ||
        flunk "the frame in OUT was not replaced"
    end

    begin "a listed output that is a $kind: not up to date, rendered again"
    rm -rf r && "$pfx" render "$FIRE" -o r "${A[@]}" || flunk "the first render failed"
    make_bad r/fire_0002.png
    pfx_run render "$FIRE" -o r "${A[@]}"
    finished && want_status 0
    [ -f r/fire_0002.png ] && [ ! -L r/fire_0002.png ] || flunk "the frame was not written again"
    end

    begin "a stale output that is a $kind: kept with a note, no hang"
    rm -rf r && "$pfx" render "$FIRE" -o r "${A[@]}" || flunk "the first render failed"
    make_bad r/fire_0005.png
    pfx_run render "$FIRE" -o r --size 48x48 --frames 0:3 --seed 3
    finished && want_status 0
    stderr_has "kept stale 'r/fire_0005.png': it changed since pfx wrote it"
    end
done

# The parts are compared with the first that is a render slice, and the
# message names that one, not a part refused before it.
begin "another render's slice is named against the slice it differs from"
rm -rf t && mkdir t && cp -r s0 s1 t/ && cp -r s1 t/s2
edit t/s0 "m['command'] = 'bake'"
edit t/s2 "m['settings']['seed'] = 4"
pfx_run assemble t/s0 t/s1 t/s2 -o t/all
finished && want_status 1
stderr_has "'t/s0/$M0' is not the manifest of a render slice"
stderr_has "'t/s2/$M1' is a slice of another render than 't/s1/$M1'"
[ ! -e t/all/fire.manifest.json ] || flunk "a manifest was written"
end

# A damaged slice manifest says why: the JSON error at file:line:col (the
# 'x' is the 18th character of line 3), or the member that is wrong.
begin "a slice manifest that is not JSON: the error at file:line:col"
rm -rf t && mkdir t && cp -r s0 s1 t/
printf '{\n  "pfx_manifest": 1,\n  "settings": {} x\n}\n' >t/s1/$M1
pfx_run assemble t/s0 t/s1 -o t/all
finished && want_status 1
stderr_has "'t/s1/$M1' is not a pfx manifest: t/s1/$M1:3:18: '}' expected near 'x'"
[ ! -e t/all/fire.manifest.json ] || flunk "a manifest was written"
end

begin "a slice manifest of another format: which members are wrong"
rm -rf t && mkdir t && cp -r s0 s1 t/
printf '{"pfx_manifest": 2, "settings": {}, "inputs": [], "outputs": []}' >t/s1/$M1
pfx_run assemble t/s0 t/s1 -o t/all
finished && want_status 1
stderr_has "'t/s1/$M1' is not a pfx manifest: not format 1 with settings"
end

begin "a slice manifest that is a FIFO: an error, no hang"
rm -rf t && mkdir t && cp -r s0 s1 t/
rm t/s1/$M1 && mkfifo t/s1/$M1
pfx_run assemble t/s0 t/s1 -o t/all
finished && want_status 1
stderr_has "'t/s1/$M1' is not a pfx manifest: not a regular file"
end

begin "a manifest input without a path: not a manifest"
rm -rf t && mkdir t && cp -r s0 s1 t/
edit t/s1 "del m['inputs'][0]['path']"
pfx_run assemble t/s0 t/s1 -o t/all
finished && want_status 1
stderr_has "'t/s1/$M1' is not a pfx manifest"
end

begin "a slice frame that is a symbolic link to a regular file is refused"
rm -rf t && mkdir t && cp -r s0 s1 t/
mv t/s1/fire_0004.png t/elsewhere.png && ln -s ../elsewhere.png t/s1/fire_0004.png
pfx_run assemble t/s0 t/s1 -o t/all
finished && want_status 1
stderr_has "cannot read 't/s1/fire_0004.png': not a regular file"
end

# big N DIR: two slices of N one-byte-ish frames built from s0 and s1's
# manifests (assemble reads no pixels without --atlas or --preview).
big() {
    "$py" - "$1" "$2" <<'PY'
import hashlib, json, os, sys
n, top = int(sys.argv[1]), sys.argv[2]
for i, (lo, hi) in enumerate([(0, n // 2), (n // 2, n)]):
    d = f"{top}/s{i}"
    os.makedirs(d)
    m = json.load(open(f"s{i}/fire.slice-000{i}-of-0002.manifest.json"))
    m["settings"]["frames"] = [lo, hi - 1]
    m["slice"]["frames"] = [0, n - 1]
    m["outputs"] = []
    for f in range(lo, hi):
        name, data = "fire_%04d.png" % f, b"%d" % f
        open(f"{d}/{name}", "wb").write(data)
        m["outputs"].append({"path": name, "sha256": hashlib.sha256(data).hexdigest()})
    json.dump(m, open(f"{d}/fire.slice-000{i}-of-0002.manifest.json", "w"))
PY
}

# Linear in the outputs: 20000 frames took 3.8 s of user CPU with the
# quadratic merge, 40000 four times that; now 0.12 s and about 0.25 s.
# 5 s of CPU leaves a wide margin for a loaded machine (the bound is CPU
# time, not the wall clock, which the links' fsyncs stretch).
begin "40000 outputs assemble in bounded time"
rm -rf b && big 40000 b
pfx_cpu=5 pfx_timeout=300
pfx_run assemble b/s0 b/s1 -o b/all
pfx_cpu=unlimited pfx_timeout=30
finished && want_status 0
stderr_has "assembled 40000 frames of 1 render"
[ "$(ls b/all | wc -l)" = 40001 ] || flunk "not 40000 frames and a manifest in b/all"
end

# fps from slice manifests: in the effect file's range and the same in
# every slice, checked before any frame is gathered. Both slices are
# edited alike (they agree) but for the last cases.
fps_case() {
    begin "$1"
    rm -rf t && mkdir t && cp -r s0 s1 t/
    edit t/s1 "$2"
    [ "${4-}" = one ] || edit t/s0 "$2"
    pfx_run assemble t/s0 t/s1 -o t/all --preview t/all/fire.webp
    finished && want_status 1
    stderr_has "$3"
    [ ! -e t/all/fire_0000.png ] || flunk "frames were gathered before the check"
    [ ! -e t/all/fire.webp ] || flunk "a preview was written"
    end
}
fps_case "fps 0 is refused" "m['settings']['fps'] = 0" "t/s1/$M1' records fps 0; it must be greater than 0 and at most 1000"
fps_case "a negative fps is refused" "m['settings']['fps'] = -30" "records fps -30; it must be greater than 0"
fps_case "fps 1e9 is refused" "m['settings']['fps'] = 1e9" "records fps 1e+09; it must be greater than 0"
fps_case "fps as a string is refused" "m['settings']['fps'] = '30'" "t/s1/$M1' records no fps (a number)"
fps_case "no fps is refused" "del m['settings']['fps']" "t/s1/$M1' records no fps (a number)"
fps_case "slices with other fps are refused" "m['settings']['fps'] = 24" \
    "t/s1/$M1' records fps 24, and 't/s0/$M0' fps 30: slices of one render share their fps" one
fps_case "a 0x48 image is refused" "m['settings']['width'] = 0" "t/s1/$M1' records an image size of 0x48, not one render can make" one

# Previews carry their hash in the manifest like every output: a preview
# damaged since is not up to date (render) and is made again (assemble).
# preview_ok FILE MANIFEST: Pillow reads FILE whole (6 frames of 48x48) and
# MANIFEST records its SHA-256.
preview_ok() {
    "$py" - "$1" "$2" <<'PY' || flunk "$1: not a whole preview, or not the hash its manifest records"
import hashlib, json, sys
from PIL import Image
path, manifest = sys.argv[1], sys.argv[2]
im = Image.open(path)
assert (im.n_frames, im.size) == (6, (48, 48)), (im.n_frames, im.size)
for k in range(im.n_frames):
    im.seek(k)
    im.load()
rec = json.load(open(manifest))["preview"]
assert rec == {"path": path, "sha256": hashlib.sha256(open(path, "rb").read()).hexdigest()}, rec
PY
}
damage() { head -c 100 "$1" >"$1.cut" && mv "$1.cut" "$1"; }

begin "render: the preview's hash is in the manifest; a damaged preview is not up to date"
rm -rf p && mkdir p
pfx_run render "$FIRE" -o p/r "${A[@]}" --preview p/r.webp
finished && want_status 0
preview_ok p/r.webp p/r/fire.manifest.json
damage p/r.webp
pfx_run render "$FIRE" -o p/r --size 48x48 --frames 0:5 --seed 3 --preview p/r.webp
finished && want_status 0
grep -q "up to date" "$work/err" && flunk "a damaged preview was taken for up to date"
preview_ok p/r.webp p/r/fire.manifest.json
pfx_run render "$FIRE" -o p/r --size 48x48 --frames 0:5 --seed 3 --preview p/r.webp
stderr_has "is up to date in 'p/r'"
end

begin "assemble: the preview's hash is in the manifest; a damaged preview is made again"
rm -rf p && mkdir p
pfx_run assemble s0 s1 -o p/all --preview p/all.webp
finished && want_status 0
preview_ok p/all.webp p/all/fire.manifest.json
damage p/all.webp
pfx_run assemble s0 s1 -o p/all --preview p/all.webp
finished && want_status 0
preview_ok p/all.webp p/all/fire.manifest.json
before=$(stat -c %i:%Y.%y p/all.webp)
pfx_run assemble s0 s1 -o p/all --preview p/all.webp
finished && want_status 0
[ "$(stat -c %i:%Y.%y p/all.webp)" = "$before" ] || flunk "an intact preview of the same frames was made again"
end

# A slice frame whose header claims 20000x20000 (16 rows of data, a few KB
# on disk, 1.6 GB decoded): --preview checks the header against the size the manifest
# records and refuses it before allocating, within 1 GiB of address space
# and 5 s of CPU; so does --atlas.
begin "a 20000x20000 PNG frame is refused before it is decoded (preview, atlas)"
rm -rf t && mkdir t && cp -r s0 s1 t/
"$py" - t/s1/fire_0004.png <<'PY'
import struct, sys, zlib
def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
ihdr = struct.pack(">IIBBBBB", 20000, 20000, 8, 6, 0, 0, 0)
idat = zlib.compress(b"\0" * (1 + 4 * 20000) * 16, 9)  # 16 rows of the 20000
open(sys.argv[1], "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", idat) +
                              chunk(b"IEND", b""))
PY
edit t/s1 "[o.update(sha256=sha('t/s1/fire_0004.png')) for o in m['outputs'] if o['path'] == 'fire_0004.png']"
pfx_vm=1048576 pfx_cpu=5
pfx_run assemble t/s0 t/s1 -o t/all --preview t/all.webp
pfx_vm=unlimited pfx_cpu=unlimited
finished && want_status 1
stderr_has "'t/all/fire_0004.png' is 20000x20000, not the 48x48 of the render; it is not read"
[ ! -e t/all.webp ] || flunk "a preview was written"
[ ! -e t/all/fire.manifest.json ] || flunk "a manifest was written"
pfx_vm=1048576 pfx_cpu=5
pfx_run assemble t/s0 t/s1 -o t/atlas --atlas
pfx_vm=unlimited pfx_cpu=unlimited
finished && want_status 1
stderr_has "'t/atlas/fire_0004.png' is 20000x20000, not 48x48 like the render's frames; it is not read"
[ ! -e t/atlas/fire_atlas.png ] || flunk "an atlas was written"
end

begin "--atlas: frames the manifest says are too large together are refused before any is read"
rm -rf t && mkdir t && cp -r s0 s1 t/
for s in t/s0 t/s1; do edit $s "m['settings'].update(width=16384, height=8192)"; done
pfx_run assemble t/s0 t/s1 -o t/all --atlas
finished && want_status 1
stderr_has "an atlas of 6 frames of 16384x8192 would hold 3072 MiB of frames, over the 1024 MiB bound"
grep -q "is 48x48" "$work/err" && flunk "a frame was read before the bound was checked"
end

summary
