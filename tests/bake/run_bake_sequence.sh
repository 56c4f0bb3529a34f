#!/usr/bin/env bash
# One cache file a frame: a run of '#' in -o's file name is the frame
# number, zero-padded to the run's length (cache_####.ply: cache_0010.ply),
# as Blender and Houdini spell a frame sequence. For CSV, PLY and pcache
# each file is byte for byte the bake of that frame alone (--frames K:K);
# the PLY files read back with meshio hold that frame's particles and,
# together, every row of the one-file bake of the range. The manifest
# (cache_####.ply.manifest.json) lists the files: a re-run is up to date, a
# narrower range removes the files it no longer makes.
#
#   bash run_bake_sequence.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" bake_sequence "$@"
cd "$src" || exit 2
FIRE=effects/fire.yaml
R=(--seed 3 -q)

# names DIR: the files in DIR but the manifest, on one line.
names() { (cd "$1" && ls | grep -v 'manifest.json$' | tr '\n' ' '); }

for fmt in csv ply pcache; do
    begin "$fmt: cache_####.$fmt writes frames 10 to 14, each the bake of that frame alone"
    pfx_run bake "$FIRE" -o "$work/$fmt/cache_####.$fmt" --frames 10:14 "${R[@]}"
    if finished && want_status 0; then
        want=""
        for k in 10 11 12 13 14; do want+="cache_00$k.$fmt "; done
        [ "$(names "$work/$fmt")" = "$want" ] || flunk "wrote $(names "$work/$fmt")"
        for k in 10 11 12 13 14; do
            pfx_run bake "$FIRE" -o "$work/alone_$k.$fmt" --frames "$k:$k" "${R[@]}"
            want_status 0
            cmp -s "$work/alone_$k.$fmt" "$work/$fmt/cache_00$k.$fmt" ||
                flunk "cache_00$k.$fmt differs from --frames $k:$k"
        done
    fi
    end
done

begin "meshio reads each PLY as its frame's particles, together the one-file bake's"
pfx_run bake "$FIRE" -o "$work/all.ply" --frames 10:14 "${R[@]}"
want_status 0
out=$("$py" - "$work" <<'PY'
import sys
import numpy as np
import meshio
d = sys.argv[1]
whole = meshio.read(d + "/all.ply", file_format="ply")
wf = np.asarray(whole.point_data["frame"])
for k in range(10, 15):
    m = meshio.read("%s/ply/cache_%04d.ply" % (d, k), file_format="ply")
    f = np.asarray(m.point_data["frame"])
    sel = wf == k
    if len(m.points) == 0 or not np.all(f == k):
        print("frame %d: %d points, frames %s" % (k, len(m.points), sorted(set(f.tolist()))))
    elif len(m.points) != sel.sum() or not np.array_equal(m.points, whole.points[sel]):
        print("frame %d: %d points, the one-file bake has %d for it, or other positions"
              % (k, len(m.points), sel.sum()))
PY
)
[ -z "$out" ] || flunk "$out"
end

begin "a number wider than the run is written whole; --frames A:B:S takes every S-th"
pfx_run bake "$FIRE" -o "$work/short/c_#.csv" --frames 8:12:2 "${R[@]}"
want_status 0
[ "$(names "$work/short")" = "c_10.csv c_12.csv c_8.csv " ] || flunk "wrote $(names "$work/short")"
for k in 8 10 12; do
    [ "$(tail -n +2 "$work/short/c_$k.csv" | cut -d, -f1 | sort -u)" = "$k" ] ||
        flunk "c_$k.csv holds other frames"
done
end

begin "the manifest lists the files; a re-run is up to date; a narrower one removes the rest"
m="$work/ply/cache_####.ply.manifest.json"
n=$("$py" -c 'import json,sys; print(" ".join(sorted(o["path"] for o in json.load(open(sys.argv[1]))["outputs"])))' "$m")
[ "$n" = "cache_0010.ply cache_0011.ply cache_0012.ply cache_0013.ply cache_0014.ply" ] ||
    flunk "the manifest lists '$n'"
pfx_run bake "$FIRE" -o "$work/ply/cache_####.ply" --frames 10:14 --seed 3
want_status 0
stderr_has "is up to date"
pfx_run bake "$FIRE" -o "$work/ply/cache_####.ply" --frames 10:12 --seed 3 --depfile "$work/d"
want_status 0
stderr_has "2 stale removed"
[ "$(names "$work/ply")" = "cache_0010.ply cache_0011.ply cache_0012.ply " ] ||
    flunk "left $(names "$work/ply")"
# Make reads '#' as a comment: the depfile escapes it.
grep -qF "$work/ply/cache_\#\#\#\#.ply.manifest.json:" "$work/d" ||
    flunk "the depfile's target is not the manifest: $(head -n 1 "$work/d")"
end

# A file of the sequence that is an input of the run (the mesh m_0001.obj
# under -o m_####.obj) is refused before any work, as a one-file -o is:
# the mesh is intact and no frame is written. With --frames 0:2:2 frame 1
# is not written, so the same names are fine.
begin "a sequence that would write over its own mesh is refused before any frame"
mkdir -p "$work/in"
cp effects/torus.obj "$work/in/m_0001.obj"
sed 's/torus.obj/m_0001.obj/' effects/mesh_emitter.yaml >"$work/in/fx.yaml"
h=$(sha256sum "$work/in/m_0001.obj" | cut -d' ' -f1)
pfx_run bake "$work/in/fx.yaml" -o "$work/in/m_####.obj" --format csv --frames 0:2 "${R[@]}"
want_status 1
stderr_has "cannot write '$work/in/m_0001.obj': it is the input '$work/in/m_0001.obj' of this run"
[ "$(sha256sum "$work/in/m_0001.obj" | cut -d' ' -f1)" = "$h" ] || flunk "the mesh was overwritten"
[ "$(names "$work/in")" = "fx.yaml m_0001.obj " ] || flunk "wrote $(names "$work/in")"
pfx_run bake "$work/in/fx.yaml" -o "$work/in/m_####.obj" --format csv --frames 0:2:2 "${R[@]}"
want_status 0
[ "$(names "$work/in")" = "fx.yaml m_0000.obj m_0001.obj m_0002.obj " ] || flunk "wrote $(names "$work/in")"
[ "$(sha256sum "$work/in/m_0001.obj" | cut -d' ' -f1)" = "$h" ] || flunk "the mesh was overwritten"
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
usage_error "two runs of '#'" "-o takes one run of '#'" bake "$FIRE" -o "$work/u/a_##_##.csv"
usage_error "'#' in a directory" "-o takes one run of '#'" bake "$FIRE" -o "$work/u#/a.csv"
begin "the usage errors wrote nothing"
[ ! -e "$work/u" ] && [ ! -e "$work/u#" ] || flunk "output left behind"
end

summary
