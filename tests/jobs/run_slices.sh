#!/usr/bin/env bash
# Slices and assemble: --slice I/N and --slice-env VAR render contiguous
# parts of the frame range, each simulating from t = 0, and `pfx assemble`
# gathers them. The assembled frames must equal a one-process render byte
# for byte (cmp), and the assembled manifest must carry the one-process
# render's bake key. Missing, doubled or damaged slices are errors.
#
#   bash run_slices.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" slices "$@"
cd "$work" || exit 2
FIRE=$src/effects/fire.yaml
A=(--size 48x48 --frames 20:30 --seed 3 -q)

key() { "$py" -c 'import json,sys; print(json.load(open(sys.argv[1]))["bake_key"])' "$1"; }
# same_frames DIR: DIR holds exactly the one-process frames, byte for byte.
same_frames() {
    local f
    for f in one/fire_*.png; do
        cmp -s "$f" "$1/${f#one/}" || flunk "$1/${f#one/} differs from the one-process frame"
    done
    [ "$(ls "$1"/fire_*.png | wc -l)" = "$(ls one/fire_*.png | wc -l)" ] || flunk "$1 holds another number of frames"
}

begin "the one-process render"
pfx_run render "$FIRE" -o one "${A[@]}"
want_status 0
end

begin "four slices in four directories, assembled"
for i in 0 1 2 3; do
    pfx_run render "$FIRE" -o s$i "${A[@]}" --slice $i/4
    want_status 0
done
# 11 frames in 4 slices: 2, 3, 3, 3 frames, contiguous.
[ "$(ls s0/fire_*.png | tr '\n' ' ')" = "s0/fire_0020.png s0/fire_0021.png " ] || flunk "slice 0: $(ls s0)"
[ "$(ls s3/fire_*.png | tr '\n' ' ')" = "s3/fire_0028.png s3/fire_0029.png s3/fire_0030.png " ] || flunk "slice 3: $(ls s3)"
pfx_run assemble s0 s1 s2 s3 -o all
want_status 0
stderr_has "assembled 11 frames of 1 render in 'all' (11 linked"
same_frames all
[ "$(key all/fire.manifest.json)" = "$(key one/fire.manifest.json)" ] || flunk "the assembled key differs from the one-process key"
[ "$(stat -c %h all/fire_0025.png)" -ge 2 ] || flunk "frames are not hard links"
end

begin "assemble --atlas --preview: the sheet of a one-process render, and its key"
pfx_run render "$FIRE" -o one-atlas "${A[@]}" --atlas --padding 3
want_status 0
pfx_run assemble s0 s1 s2 s3 -o all-atlas --atlas --padding 3
want_status 0
cmp -s one-atlas/fire_atlas.png all-atlas/fire_atlas.png || flunk "the sheets differ"
cmp -s one-atlas/fire_atlas.json all-atlas/fire_atlas.json || flunk "the atlas JSON differs"
[ "$(key all-atlas/fire.manifest.json)" = "$(key one-atlas/fire.manifest.json)" ] || flunk "the keys differ"
pfx_run assemble s0 s1 s2 s3 -o all-preview --preview all-preview/fire.webp
want_status 0
[ -s all-preview/fire.webp ] || flunk "no preview"
end

begin "a one-process render over the assembly finds it up to date"
pfx_run render "$FIRE" -o all --size 48x48 --frames 20:30 --seed 3
want_status 0
stderr_has "is up to date in 'all'"
end

begin "slices from the environment, sharing one directory"
JOB_COMPLETION_INDEX=0 pfx_run render "$FIRE" -o shared "${A[@]}" --slice-env JOB_COMPLETION_INDEX --slice-count 3
want_status 0
AWS_BATCH_JOB_ARRAY_INDEX=1 pfx_run render "$FIRE" -o shared "${A[@]}" --slice-env AWS_BATCH_JOB_ARRAY_INDEX --slice-count 3
want_status 0
SLURM_ARRAY_TASK_ID=2 pfx_run render "$FIRE" -o shared "${A[@]}" --slice-env SLURM_ARRAY_TASK_ID --slice-count 3
want_status 0
[ "$(ls shared/*.slice-*.manifest.json | wc -l)" = 3 ] || flunk "not three slice manifests"
pfx_run assemble shared -o shared-all
want_status 0
same_frames shared-all
end

begin "more slices than frames: the empty ones still count"
for i in 0 1 2 3 4; do
    pfx_run render "$FIRE" -o few --size 48x48 --frames 0:2 --seed 3 --slice $i/5
    want_status 0
    # 3 frames in 5 slices: slices 0 and 2 are empty.
    [ $i != 0 ] || stderr_has "slice 0 of 5 of '$FIRE' has no frames (3 frames in all)"
done
pfx_run assemble few -o few-all
want_status 0
stderr_has "assembled 3 frames"
end

begin "a missing slice is an error and writes no manifest"
pfx_run assemble s0 s1 s3 -o gap
want_status 1
stderr_has "slice 2 of 4 is missing"
[ ! -e gap/fire.manifest.json ] || flunk "a manifest was written"
end

begin "a slice given twice is an error"
cp -r s1 s1-again
pfx_run assemble s0 s1 s1-again s2 s3 -o twice
want_status 1
stderr_has "slice 1 of 4 is in both"
end

begin "a damaged frame is an error"
cp -r s2 s2-bad && printf 'x' >>s2-bad/fire_0026.png
pfx_run assemble s0 s1 s2-bad s3 -o damaged
want_status 1
stderr_has "'s2-bad/fire_0026.png' does not match the hash its slice's manifest records"
end

begin "slices of another render do not mix"
pfx_run render "$FIRE" -o other "${A[@]}" --seed 4 --slice 2/4
want_status 0
pfx_run assemble s0 s1 other s3 -o mixed
want_status 1
stderr_has "is a slice of another render"
end

begin "slices from another build of pfx do not mix"
cp -r s2 s2-older
"$py" - s2-older/fire.slice-0002-of-0004.manifest.json <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["pfx_results"] -= 1  # as a build before the last change to pfx's output wrote it
json.dump(m, open(sys.argv[1], "w"))
PY
pfx_run assemble s0 s1 s2-older s3 -o older
want_status 1
stderr_has "s2-older/fire.slice-0002-of-0004.manifest.json' was rendered by another build of pfx than"
[ ! -e older/fire.manifest.json ] || flunk "a manifest was written"
end

begin "slices of a build that recorded no pfx_results: a key, not this build's"
for i in 0 1 2 3; do cp -r s$i o$i; done
"$py" - o?/fire.slice-*.manifest.json <<'PY'
import json, sys
for path in sys.argv[1:]:
    m = json.load(open(path))
    del m["pfx_results"]
    json.dump(m, open(path, "w"))
PY
pfx_run assemble o0 o1 o2 o3 -o old-all
want_status 0
"$py" -c 'import json,sys; m = json.load(open(sys.argv[1])); sys.exit(len(m.get("bake_key", "")) != 64 or "pfx_results" in m)' old-all/fire.manifest.json ||
    flunk "the assembled manifest has no key, or a pfx_results its slices did not record"
pfx_run render "$FIRE" -o old-all "${A[@]}"
want_status 0
"$py" -c 'import json,sys; sys.exit("pfx_results" not in json.load(open(sys.argv[1])))' old-all/fire.manifest.json ||
    flunk "this build took the old slices' key for its own (no new manifest)"
end

usage() {
    begin "$1"
    shift
    local want=$1
    shift
    pfx_run "$@"
    want_status 2
    stderr_has "$want"
    end
}
usage "--slice 4/4 is a usage error" "--slice takes I/N with 0 <= I < N" render "$FIRE" -o u --slice 4/4
usage "--slice-env without a count" "--slice-env needs --slice-count N" render "$FIRE" -o u --slice-env X
usage "--slice-env with the variable unset" "--slice-env PFX_NO_SUCH_VAR: the variable must hold a slice index from 0 to 3, got '(unset)'" \
    render "$FIRE" -o u --slice-env PFX_NO_SUCH_VAR --slice-count 4
usage "assemble without -o" "assemble needs -o OUT" assemble s0

summary
