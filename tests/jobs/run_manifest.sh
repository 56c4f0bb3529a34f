#!/usr/bin/env bash
# Manifests: <name>.manifest.json beside a render's frames and OUT.manifest.json
# beside a bake, read by Python's json module and checked against files
# hashed by Python's hashlib (not by pfx): every input (the effect, its
# mesh) and every output with its SHA-256, and a bake key. A re-run with the
# same key and intact outputs does nothing; --force, a changed input or a
# changed output runs again; files the previous manifest listed and the new
# one does not are removed, other files never.
#
#   bash run_manifest.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" manifest "$@"
cd "$work" || exit 2
# A copy of the mesh example, so that the test may change its inputs.
cp "$src/effects/mesh_emitter.yaml" "$src/effects/torus.obj" "$work/"
E=$work/mesh_emitter.yaml
R=(--size 48x48 --seed 5)

# check_manifest MANIFEST DIR: the manifest lists the inputs and outputs
# with their true hashes; prints ok/FAIL lines.
check_manifest() {
    "$py" - "$@" <<'PY'
import hashlib, json, os, sys
man, d = sys.argv[1], sys.argv[2]
sha = lambda p: hashlib.sha256(open(p, "rb").read()).hexdigest()
m = json.load(open(man))
bad = []
for k in ("pfx_version", "pfx_results", "command", "settings", "inputs", "outputs", "bake_key"):
    if k not in m:
        bad.append("no " + k)
for i in m.get("inputs", []):
    if sha(i["path"]) != i["sha256"]:
        bad.append("input %s hash" % i["path"])
names = [os.path.basename(i["path"]) for i in m.get("inputs", [])]
if names[:2] != ["mesh_emitter.yaml", "torus.obj"]:
    bad.append("inputs %s" % names)
for o in m.get("outputs", []):
    if sha(os.path.join(d, o["path"])) != o["sha256"]:
        bad.append("output %s hash" % o["path"])
if len(m.get("bake_key", "")) != 64:
    bad.append("bake key %r" % m.get("bake_key"))
print(("FAIL %s: " % man + "; ".join(bad)) if bad else
      "ok   %s lists %d inputs and %d outputs with their SHA-256" %
      (os.path.basename(man), len(m["inputs"]), len(m["outputs"])))
PY
}

begin "render writes a manifest"
pfx_run render "$E" -o frames --frames 0:5 "${R[@]}"
finished && want_status 0
[ -f frames/mesh_emitter.manifest.json ] || flunk "no frames/mesh_emitter.manifest.json"
end
tally "$(check_manifest frames/mesh_emitter.manifest.json frames)"
key() { "$py" -c 'import json,sys; print(json.load(open(sys.argv[1]))["bake_key"])' "$1"; }
key1=$(key frames/mesh_emitter.manifest.json)

begin "a second render with the same key does nothing"
stamp=$(stat -c %Y.%N frames/mesh_emitter_0003.png)
sleep 1
pfx_run render "$E" -o frames --frames 0:5 "${R[@]}"
want_status 0
stderr_has "is up to date in 'frames'"
[ "$(stat -c %Y.%N frames/mesh_emitter_0003.png)" = "$stamp" ] || flunk "a frame was rewritten"
end

begin "--force renders again, to the same bytes and key"
cp frames/mesh_emitter_0003.png before.png
pfx_run render "$E" -o frames --frames 0:5 "${R[@]}" --force
want_status 0
stderr_has "rendered"
cmp -s before.png frames/mesh_emitter_0003.png || flunk "frame 3 differs"
[ "$(key frames/mesh_emitter.manifest.json)" = "$key1" ] || flunk "the key changed"
end

begin "a damaged output is rendered again"
printf 'x' >>frames/mesh_emitter_0002.png
pfx_run render "$E" -o frames --frames 0:5 "${R[@]}"
want_status 0
stderr_has "rendered"
end
tally "$(check_manifest frames/mesh_emitter.manifest.json frames)"

# The key as the man page defines it: the SHA-256 of the sorted, compact
# JSON of pfx_version, pfx_results, command, settings and inputs. With
# `older`, the manifest is rewritten as a build of the revision before
# would have written it (key included).
rekey() {
    "$py" - "$@" <<'PY'
import hashlib, json, sys
path = sys.argv[1]
m = json.load(open(path))
if len(sys.argv) > 2:
    m["pfx_results"] -= 1
keyed = {k: m[k] for k in ("pfx_version", "pfx_results", "command", "settings", "inputs")}
text = json.dumps(keyed, sort_keys=True, separators=(",", ":"), ensure_ascii=False)
key = hashlib.sha256(text.encode()).hexdigest()
if len(sys.argv) > 2:
    m["bake_key"] = key
    json.dump(m, open(path, "w"))
print(key)
PY
}

begin "the key covers the results revision; another revision's outputs are redone"
[ "$(rekey frames/mesh_emitter.manifest.json)" = "$(key frames/mesh_emitter.manifest.json)" ] ||
    flunk "the key is not the SHA-256 of version, results, command, settings and inputs"
rekey frames/mesh_emitter.manifest.json older >/dev/null
pfx_run render "$E" -o frames --frames 0:5 "${R[@]}"
want_status 0
stderr_has "rendered"
[ "$(key frames/mesh_emitter.manifest.json)" = "$key1" ] || flunk "the key changed"
end

begin "a changed setting changes the key"
pfx_run render "$E" -o frames --frames 0:5 "${R[@]}" --seed 6
want_status 0
stderr_has "rendered"
[ "$(key frames/mesh_emitter.manifest.json)" != "$key1" ] || flunk "the same key"
end

begin "a changed mesh changes the key"
key2=$(key frames/mesh_emitter.manifest.json)
echo "# changed" >>torus.obj
pfx_run render "$E" -o frames --frames 0:5 "${R[@]}" --seed 6
want_status 0
stderr_has "rendered"
[ "$(key frames/mesh_emitter.manifest.json)" != "$key2" ] || flunk "the same key"
end

# Stale outputs: 0:5 then 0:2 removes frames 3 to 5, and only those.
begin "stale frames are removed, other files kept"
echo mine >frames/notes.txt
cp frames/mesh_emitter_0005.png frames/mesh_emitter_0005.png.keep
printf 'edited' >>frames/mesh_emitter_0004.png
pfx_run render "$E" -o frames --frames 0:2 "${R[@]}" --seed 6
want_status 0
stderr_has "2 stale removed"
stderr_has "kept stale 'frames/mesh_emitter_0004.png': it changed since pfx wrote it"
[ ! -e frames/mesh_emitter_0003.png ] || flunk "frame 3 is still there"
[ ! -e frames/mesh_emitter_0005.png ] || flunk "frame 5 is still there"
[ -e frames/mesh_emitter_0004.png ] || flunk "the edited frame 4 was removed"
[ -e frames/notes.txt ] && [ -e frames/mesh_emitter_0005.png.keep ] || flunk "a file pfx did not write was removed"
[ -e frames/mesh_emitter_0002.png ] || flunk "frame 2 is gone"
end
tally "$(check_manifest frames/mesh_emitter.manifest.json frames)"

begin "a failed render leaves the manifest as it was"
cp frames/mesh_emitter.manifest.json before.json
rm frames/mesh_emitter_0001.png && mkdir frames/mesh_emitter_0001.png
pfx_run render "$E" -o frames --frames 0:2 "${R[@]}" --seed 6 --force
want_status 1
cmp -s before.json frames/mesh_emitter.manifest.json || flunk "the manifest changed"
rmdir frames/mesh_emitter_0001.png
pfx_run render "$E" -o frames --frames 0:2 "${R[@]}" --seed 6
want_status 0
stderr_has "rendered"
end

begin "a manifest cannot make pfx remove files outside its directory"
mkdir -p evil && echo precious >precious.txt
h=$(sha256sum precious.txt | cut -d' ' -f1)
cat >evil/mesh_emitter.manifest.json <<JSON
{"pfx_manifest": 1, "settings": {}, "inputs": [], "bake_key": "0",
 "outputs": [{"path": "../precious.txt", "sha256": "$h"},
             {"path": "$work/precious.txt", "sha256": "$h"}]}
JSON
pfx_run render "$E" -o evil --frames 0 "${R[@]}"
want_status 0
[ -e precious.txt ] || flunk "precious.txt was removed"
end

# Bakes: OUT.manifest.json, the same rules.
begin "bake writes OUT.manifest.json and skips an unchanged re-run"
pfx_run bake "$E" -o b/cache.ply --frames 0:4 --seed 5
want_status 0
[ -f b/cache.ply.manifest.json ] || flunk "no b/cache.ply.manifest.json"
pfx_run bake "$E" -o b/cache.ply --frames 0:4 --seed 5
want_status 0
stderr_has "is up to date in 'b/cache.ply'"
pfx_run bake "$E" -o b/cache.ply --frames 0:4 --seed 5 --every 2
want_status 0
stderr_has "baked"
end
"$py" - b/cache.ply.manifest.json <<'PY' >report.txt
import hashlib, json, sys
m = json.load(open(sys.argv[1]))
o = m["outputs"]
ok = (len(o) == 1 and o[0]["path"] == "cache.ply" and
      o[0]["sha256"] == hashlib.sha256(open("b/cache.ply", "rb").read()).hexdigest() and
      m["settings"]["format"] == "ply" and m["settings"]["every"] == 2)
print("ok   the bake's manifest lists cache.ply with its hash" if ok else "FAIL the bake's manifest: %r" % m)
PY
tally "$(cat report.txt)"

begin "bake -o - writes no manifest"
mkdir -p so && cd so || exit 2
pfx_run bake "$E" -o - --frames 0 --seed 5
want_status 0
[ -z "$(ls -A)" ] || flunk "files were written: $(ls -A)"
cd "$work" || exit 2
end

# A frame of an earlier run used as this run's texture, directly or through
# a link, with fewer frames this time: it is stale by the manifest but an
# input now, so it is kept (compared as a file: device and inode).
begin "a stale output that is an input of the new run is kept"
mkdir -p tex && cd tex || exit 2
cp "$E" "$src/effects/torus.obj" .
pfx_run render mesh_emitter.yaml -o frames --frames 0:5 "${R[@]}"
want_status 0
h4=$(sha256sum frames/mesh_emitter_0004.png | cut -d' ' -f1)
ln -s frames/mesh_emitter_0005.png five.png
sed 's|^    blend: add|    blend: add\n    texture: frames/mesh_emitter_0004.png\n  again:\n    shape: { type: sphere, radius: 0.2 }\n    rate: 50\n    lifetime: 0.5\n    size: 0.1\n    texture: five.png|' \
    mesh_emitter.yaml >next.yaml && mv next.yaml mesh_emitter.yaml
pfx_run render mesh_emitter.yaml -o frames --frames 0:2 "${R[@]}"
want_status 0
stderr_has "1 stale removed"
stderr_has "kept stale 'frames/mesh_emitter_0004.png': it is an input of this run"
stderr_has "kept stale 'frames/mesh_emitter_0005.png': it is an input of this run"
[ ! -e frames/mesh_emitter_0003.png ] || flunk "frame 3 is still there"
[ "$(sha256sum frames/mesh_emitter_0004.png | cut -d' ' -f1)" = "$h4" ] || flunk "frame 4, a texture, was removed or changed"
[ -e five.png ] || flunk "frame 5, a texture through a link, was removed"
cd "$work" || exit 2
end

begin "a missing mesh is an error, not ignored"
sed 's/torus.obj/gone.obj/' "$E" >gone.yaml
pfx_run render gone.yaml -o gone --frames 0 "${R[@]}"
want_status 1
stderr_has "gone.obj"
end

summary
