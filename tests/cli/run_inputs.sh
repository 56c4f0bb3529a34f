#!/usr/bin/env bash
# How render and bake treat their inputs and the names they write: an
# output that is one of the run's inputs is refused and the input kept; an
# effect read from a pipe is hashed as the bytes parsed (a changed effect
# renders again, a named FIFO is read once); a stem that is a directory's
# name, or a name too long for its directory, fails before any frame.
#
#   bash run_inputs.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" inputs "$@"
cd "$work" || exit 2
pfx_timeout=30
cp "$src/effects/mesh_emitter.yaml" "$src/effects/torus.obj" "$src/effects/fountain.yaml" .
mkdir -p tex/textures
cp "$src/effects/fire.yaml" tex/ && cp "$src/effects/textures/"*.png tex/textures/
sum() { sha256sum "$1" | cut -c1-64; }
# Every file under the scratch directory with its hash, to prove a refused
# run wrote nothing.
snapshot() { find . -type f ! -name "*.snap" ! -name err ! -name out -exec sha256sum {} + | sort >"$1"; }

BAKE="--frames 0:3 --seed 5"
begin "bake -o its own effect is refused and the effect kept"
before=$(sum mesh_emitter.yaml)
pfx_run bake mesh_emitter.yaml $BAKE -o mesh_emitter.yaml --format csv
want_status 1
stderr_has "cannot write 'mesh_emitter.yaml': it is the input 'mesh_emitter.yaml' of this run"
[ "$(sum mesh_emitter.yaml)" = "$before" ] || flunk "the effect changed"
[ ! -e mesh_emitter.yaml.manifest.json ] || flunk "a manifest was written"
end

begin "bake -o the effect by another name (./, a symlink) is refused"
ln -s mesh_emitter.yaml link.yaml
pfx_run bake mesh_emitter.yaml $BAKE -o ./link.yaml --format csv
want_status 1
stderr_has "cannot write './link.yaml': it is the input 'mesh_emitter.yaml'"
[ "$(sum mesh_emitter.yaml)" = "$before" ] || flunk "the effect changed"
end

begin "--depfile over the effect is refused before the bake"
snapshot a.snap
pfx_run bake mesh_emitter.yaml $BAKE -o cache.csv --depfile mesh_emitter.yaml
want_status 1
stderr_has "cannot write 'mesh_emitter.yaml': it is the input"
snapshot b.snap
cmp -s a.snap b.snap || flunk "files changed: $(diff a.snap b.snap | head -3)"
end

begin "bake -o the mesh is refused and the mesh kept"
mesh=$(sum torus.obj)
pfx_run bake mesh_emitter.yaml $BAKE -o torus.obj --format ply
want_status 1
stderr_has "cannot write 'torus.obj': it is the input 'torus.obj'"
[ "$(sum torus.obj)" = "$mesh" ] || flunk "the mesh changed"
end

begin "a texture as the depfile of a render, or as a bake, is refused"
snapshot a.snap
pfx_run render tex/fire.yaml -o tex/out --frames 0:1 --size 16x16 --depfile tex/textures/fire_sheet.png
want_status 1
stderr_has "cannot write 'tex/textures/fire_sheet.png': it is the input 'tex/textures/fire_sheet.png'"
pfx_run bake tex/fire.yaml --frames 0:1 -o tex/textures/fire_sheet.png --format csv
want_status 1
stderr_has "cannot write 'tex/textures/fire_sheet.png': it is the input"
snapshot b.snap
cmp -s a.snap b.snap || flunk "files changed: $(diff a.snap b.snap | head -3)"
[ ! -e tex/out ] || flunk "the output directory was made"
end

begin "a frame that would land on a texture is refused"
mkdir -p tex2/textures && cp tex/fire.yaml tex2/ && cp tex/textures/spark_sheet.png tex2/textures/
cp tex/textures/fire_sheet.png tex2/textures/fire_0001.png
sed -i 's#textures/fire_sheet.png#textures/fire_0001.png#' tex2/fire.yaml
before=$(sum tex2/textures/fire_0001.png)
pfx_run render tex2/fire.yaml -o tex2/textures --frames 0:2 --size 16x16
want_status 1
stderr_has "cannot write 'tex2/textures/fire_0001.png': it is the input"
[ "$(sum tex2/textures/fire_0001.png)" = "$before" ] || flunk "the texture changed"
[ ! -e tex2/textures/fire_0000.png ] || flunk "a frame was rendered"
end

# An effect from a pipe: the manifest's hash is the hash of the bytes
# parsed, so a different effect through the same /dev/stdin renders again.
# (Standard input is a pipe from a process substitution: a pipe into
# pfx_run would run it in a subshell, losing $status.)
R="--frames 0:1 --size 16x16"
sed 's/^seed: .*/seed: 77/' fountain.yaml >other.yaml
begin "render /dev/stdin twice with different effects renders twice"
pfx_run render /dev/stdin -o pipe $R < <(cat fountain.yaml)
want_status 0
stderr_has "rendered '/dev/stdin'"
first=$(sum pipe/stdin_0001.png)
pfx_run render /dev/stdin -o pipe $R < <(cat other.yaml)
want_status 0
stderr_has "rendered '/dev/stdin'"
[ "$first" != "$(sum pipe/stdin_0001.png)" ] || flunk "the frame did not change"
"$py" -c 'import json,sys; m=json.load(open(sys.argv[1])); print(m["inputs"][0]["sha256"])' \
    pipe/stdin.manifest.json >hash.txt
[ "$(cat hash.txt)" = "$(sum other.yaml)" ] || flunk "manifest hash $(cat hash.txt), the effect's $(sum other.yaml)"
pfx_run render /dev/stdin -o pipe $R < <(cat other.yaml)
stderr_has "is up to date"
end

begin "render <(...) twice with different effects renders twice"
pfx_run render <(cat fountain.yaml) -o subst $R
want_status 0
stderr_has "pfx: rendered"
pfx_run render <(cat other.yaml) -o subst $R
want_status 0
stderr_has "pfx: rendered"
grep -q "$(sum other.yaml)" subst/*.manifest.json || flunk "the manifest lacks the effect's hash"
end

begin "a named FIFO is read once, not waited on again"
mkfifo fifo.yaml
timeout 30 cat fountain.yaml >fifo.yaml &
pfx_run render fifo.yaml -o fifo $R
finished && want_status 0
grep -q "$(sum fountain.yaml)" fifo/fifo.manifest.json || flunk "the manifest lacks the effect's hash"
wait
end

# Output names.
begin "an effect whose stem is '..' writes nothing outside OUT"
mkdir -p deep/in && cp fountain.yaml 'deep/in/...yaml'
snapshot a.snap
pfx_run render deep/in/...yaml fountain.yaml -o deep/out/x $R
want_status 1
stderr_has "cannot render 'deep/in/...yaml': its outputs would be named after '..'"
snapshot b.snap
cmp -s a.snap b.snap || flunk "files changed: $(diff a.snap b.snap | head -3)"
[ ! -e deep/out ] || flunk "something was written: $(find deep/out | head -3)"
cp fountain.yaml deep/in/..yaml
pfx_run render deep/in/..yaml -o deep/out $R
want_status 1
stderr_has "its outputs would be named after '.'"
end

begin "a 245-byte stem is refused before any frame is rendered"
long=$(printf 'a%.0s' $(seq 245))
cp fountain.yaml "$long.yaml"
pfx_run render "$long.yaml" -o long $R
want_status 1
stderr_has "$long.manifest.json': File name too long"
[ -z "$(find long -type f 2>/dev/null)" ] || flunk "files were written: $(find long -type f | head -2)"
pfx_run render "$long.yaml" -o long $R --slice 1/2
want_status 1
stderr_has ".slice-0001-of-0002.manifest.json': File name too long"
pfx_run bake "$long.yaml" $BAKE -o "long/$long.csv"
want_status 1
stderr_has ".csv.manifest.json': File name too long"
[ -z "$(find long -type f 2>/dev/null)" ] || flunk "files were written"
end

begin "a 241-byte stem, whose names all fit, renders"
long=$(printf 'b%.0s' $(seq 241))
cp fountain.yaml "$long.yaml"
pfx_run render "$long.yaml" -o long2 $R
want_status 0
[ -f "long2/${long}_0001.png" ] && [ -f "long2/$long.manifest.json" ] || flunk "missing outputs"
end

# A file name that is not UTF-8 (Latin-1 'café'): every JSON pfx writes
# stays valid, keeps the rest, and carries the exact bytes in
# "<key>_base64" beside a readable form with U+FFFD.
name=$(printf 'caf\xe9')
mkdir -p latin && cp fountain.yaml "latin/$name.yaml"
printf 'pfx: 1\nbogus: 1\n' >"latin/$name-bad.yaml"
# check_json KIND FILE WANT: each JSON document (KIND lines: each line
# that starts with '{'; doc: the whole file) is UTF-8 and parses, and the members named carry WANT's bytes.
check_json() {
    "$py" - "$@" <<'PY'
import base64, json, sys
kind, path, want = sys.argv[1], sys.argv[2], sys.argv[3].encode("utf-8", "surrogateescape")
raw = open(path, "rb").read()
try:
    docs = [json.loads(l.decode("utf-8")) for l in raw.splitlines() if l.startswith(b"{")] \
        if kind == "lines" else [json.loads(raw.decode("utf-8"))]
except ValueError as e:
    print("FAIL %s: not UTF-8 JSON: %s" % (path, e)); sys.exit()
found = []
def walk(v):
    if isinstance(v, dict):
        for k, x in v.items():
            if k.endswith("_base64"):
                found.append(base64.b64decode(x))
            else:
                walk(x)
    elif isinstance(v, list):
        for x in v: walk(x)
for d in docs: walk(d)
if not docs or not found or not all(want in f for f in found):
    print("FAIL %s: %d documents, names %r, none with %r" % (path, len(docs), found[:3], want))
else:
    print("ok   %s: %d documents, %d names hold the exact bytes" % (path.rsplit("/", 1)[-1], len(docs), len(found)))
PY
}

begin "validate --format json on a non-UTF-8 name"
pfx_run validate --format json "latin/$name-bad.yaml"
want_status 1
grep -q '"rule":"PFX2001"' "$work/err" || flunk "the unknown key's line is missing"
end
tally "$(check_json lines "$work/err" "latin/$name-bad.yaml")"

begin "render a non-UTF-8 name with --progress json, --atlas, --depfile"
pfx_run render "latin/$name.yaml" -o latin/out $R --progress json --atlas --depfile "latin/$name.d"
want_status 0
[ "$(grep -c '"event":"frame"' "$work/err")" = 2 ] || flunk "not 2 frame lines"
[ -f "latin/out/${name}_atlas.png" ] || flunk "no atlas"
head -1 "latin/$name.d" | grep -qF "latin/out/$name.manifest.json:" || flunk "the depfile's target"
grep -qxF "  latin/$name.yaml" "latin/$name.d" || flunk "the depfile lacks the effect: $(cat -v "latin/$name.d")"
end
tally "$(check_json lines "$work/err" "latin/$name.yaml")"
tally "$(check_json doc "latin/out/$name.manifest.json" "$name")"
tally "$(check_json doc "latin/out/${name}_atlas.json" "${name}_atlas.png")"

begin "info --format json on a non-UTF-8 name"
pfx_run info --format json "latin/$name.yaml"
want_status 0
end
tally "$(check_json doc "$work/out" "latin/$name.yaml")"

begin "the non-UTF-8 render is up to date the second time, its stale frame removed the third"
pfx_run render "latin/$name.yaml" -o latin/out $R --atlas
stderr_has "is up to date"
pfx_run render "latin/$name.yaml" -o latin/out --frames 0:0 --size 16x16
want_status 0
stderr_has "stale removed"
[ ! -e "latin/out/${name}_0001.png" ] || flunk "the stale frame is still there"
end

# A preview with a non-UTF-8 name is hashed in the manifest like every
# output, so the second run is up to date.
begin "a non-UTF-8 preview name: recorded in the manifest, up to date the second time"
pfx_run render "latin/$name.yaml" -o latin/pv $R --preview "latin/pv/$name.webp"
want_status 0
pfx_run render "latin/$name.yaml" -o latin/pv $R --preview "latin/pv/$name.webp"
want_status 0
stderr_has "is up to date"
end

begin "make reads the non-UTF-8 name from the depfile"
printf 'all: latin/out/%s.manifest.json\nlatin/out/%s.manifest.json:\n\t$(file >made,[$^])\ninclude latin/%s.d\n' \
    "$name" "$name" "$name" >Makefile.latin
make -s -f Makefile.latin -B >/dev/null 2>&1 || flunk "make failed"
[ "$(cat made)" = "[latin/$name.yaml]" ] || flunk "make read $(cat -v made)"
end

summary
