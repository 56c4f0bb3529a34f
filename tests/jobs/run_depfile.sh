#!/usr/bin/env bash
# --depfile with real build tools: make (including the depfile), ninja
# (deps = gcc) and CMake's add_custom_command(DEPFILE) under both its
# Makefile and Ninja generators. Touching the mesh makes the tool run pfx
# again (pfx then finds the key unchanged and only refreshes the target's
# time); changing the mesh re-bakes; touching nothing runs nothing. A tool
# that is not installed is a failure: ./install-deps --test installs them.
#
#   bash run_depfile.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" depfile "$@"
cd "$work" || exit 2
sleep_tick() { sleep 1.1; } # make and ninja compare whole-second times on some file systems

# One project per tool, each with its own copy of the inputs.
# runs DIR: how many times the rule ran pfx; bakes DIR: how many times pfx baked.
# Each run of a rule appends "run" to runs.log, after pfx's summary line
# ("baked ..." when it baked, "... is up to date ..." when not).
runs() { [ -f "$1/runs.log" ] && grep -c "^run" "$1/runs.log" || echo 0; }
bakes() { [ -f "$1/runs.log" ] && grep -c "baked" "$1/runs.log" || echo 0; }
setup() {
    mkdir -p "$1/in" && cp "$src/effects/mesh_emitter.yaml" "$src/effects/torus.obj" "$1/in/"
}

# exercise NAME DIR BUILD...: the build command is run in DIR four times.
exercise() {
    local name=$1 dir=$2
    shift 2
    begin "$name: the first build bakes"
    (cd "$dir" && "$@") >"$work/$name.log" 2>&1 || flunk "the build failed: $(tail -5 "$work/$name.log")"
    [ "$(bakes "$dir")" = 1 ] || flunk "pfx baked $(bakes "$dir") times"
    end
    begin "$name: a second build runs nothing"
    sleep_tick
    (cd "$dir" && "$@") >>"$work/$name.log" 2>&1 || flunk "the build failed"
    [ "$(runs "$dir")" = 1 ] || flunk "pfx ran $(runs "$dir") times"
    end
    begin "$name: touching the mesh runs pfx, which finds nothing changed"
    sleep_tick
    touch "$dir/in/torus.obj"
    (cd "$dir" && "$@") >>"$work/$name.log" 2>&1 || flunk "the build failed"
    [ "$(runs "$dir")" = 2 ] || flunk "pfx ran $(runs "$dir") times, expected 2"
    [ "$(bakes "$dir")" = 1 ] || flunk "pfx baked again"
    sleep_tick
    (cd "$dir" && "$@") >>"$work/$name.log" 2>&1 || flunk "the build failed"
    [ "$(runs "$dir")" = 2 ] || flunk "the next build ran pfx again"
    end
    begin "$name: changing the mesh re-bakes"
    sleep_tick
    echo "# changed" >>"$dir/in/torus.obj"
    (cd "$dir" && "$@") >>"$work/$name.log" 2>&1 || flunk "the build failed"
    [ "$(bakes "$dir")" = 2 ] || flunk "pfx baked $(bakes "$dir") times, expected 2"
    end
}

BAKE="bake in/mesh_emitter.yaml --frames 0:3 --seed 5"

# make
setup mk
cat >mk/Makefile <<MK
cache.csv:
	"$pfx" $BAKE -o cache.csv --depfile cache.d 2>>runs.log; echo run >>runs.log
-include cache.d
MK
if command -v make >/dev/null; then
    exercise make mk make
    begin "make: the depfile names the effect and its mesh"
    grep -q '^cache.csv:' mk/cache.d && grep -q 'in/mesh_emitter.yaml' mk/cache.d &&
        grep -q 'in/torus.obj' mk/cache.d || flunk "cache.d: $(cat mk/cache.d)"
    end
else
    fail "make is missing"
fi

# ninja
setup nj
cat >nj/build.ninja <<NJ
rule bake
  command = "$pfx" $BAKE -o \$out --depfile \$out.d 2>>runs.log; echo run >>runs.log
  depfile = \$out.d
  deps = gcc
build cache.csv: bake in/mesh_emitter.yaml
NJ
if command -v ninja >/dev/null; then
    exercise ninja nj ninja
else
    fail "ninja is missing"
fi

# CMake, both generators.
for gen in "Unix Makefiles" Ninja; do
    d=cm-${gen%% *}
    setup "$d"
    cat >"$d/CMakeLists.txt" <<CM
cmake_minimum_required(VERSION 3.20)
project(bake NONE)
add_custom_command(OUTPUT \${CMAKE_BINARY_DIR}/cache.csv
  COMMAND sh -c "\\"$pfx\\" bake \${CMAKE_SOURCE_DIR}/in/mesh_emitter.yaml --frames 0:3 --seed 5 -o \${CMAKE_BINARY_DIR}/cache.csv --depfile \${CMAKE_BINARY_DIR}/cache.d 2>>\${CMAKE_SOURCE_DIR}/runs.log; echo run >>\${CMAKE_SOURCE_DIR}/runs.log"
  DEPFILE \${CMAKE_BINARY_DIR}/cache.d
  VERBATIM)
add_custom_target(bake ALL DEPENDS \${CMAKE_BINARY_DIR}/cache.csv)
CM
    if ! (cd "$d" && cmake -S . -B build -G "$gen") >"$work/$d.configure.log" 2>&1; then
        fail "cmake ($gen) configures" "$(tail -5 "$work/$d.configure.log")"
        continue
    fi
    exercise "cmake ($gen)" "$d" cmake --build build
done

# Textures are inputs like meshes: the depfile names them, and an edited
# texture makes the render stale.
mkdir -p tex/textures
cp "$src/effects/fire.yaml" tex/
cp "$src/effects/textures/fire_sheet.png" "$src/effects/textures/spark_sheet.png" tex/textures/
begin "the depfile names the effect's texture, and editing it renders again"
pfx_run render tex/fire.yaml -o tex/out --frames 0:1 --size 32x32 --depfile tex/fire.d
want_status 0
grep -q 'tex/textures/fire_sheet.png' tex/fire.d || flunk "fire.d: $(cat tex/fire.d)"
grep -q 'fire_sheet.png' tex/out/fire.manifest.json || flunk "the manifest lists no texture"
pfx_run render tex/fire.yaml -o tex/out --frames 0:1 --size 32x32 --depfile tex/fire.d
stderr_has "is up to date"
printf 'x' >>tex/textures/fire_sheet.png
pfx_run render tex/fire.yaml -o tex/out --frames 0:1 --size 32x32 --depfile tex/fire.d
want_status 0
stderr_has "rendered 'tex/fire.yaml'"
end

# Paths with ':', ' ', '#' and '$': escaped so that make and ninja both
# read the very paths back; a newline or a tab, which neither can carry,
# is refused before the run.
odd='in: a #1 $x'
mkdir -p "$odd" && cp "$src/effects/mesh_emitter.yaml" "$src/effects/torus.obj" "$odd/"
begin "make reads back a depfile's paths with ':', ' ', '#' and '\$'"
# (the output has no '#': a run of '#' in bake's -o is the frame number)
pfx_run bake "$odd/mesh_emitter.yaml" --frames 0:1 -o "odd:1 \$.csv" --depfile odd.d
want_status 0
printf 'all: odd\\:1\\ $$.csv\nodd\\:1\\ $$.csv:\n\t$(file >made,[$^])\ninclude odd.d\n' >Makefile.odd
make -s -f Makefile.odd -B >/dev/null 2>"$work/make.err" || flunk "make failed: $(cat "$work/make.err")"
[ "$(cat made)" = "[$odd/mesh_emitter.yaml $odd/torus.obj]" ] || flunk "make read $(cat made 2>/dev/null)"
end
begin "ninja reads back the same paths"
mkdir -p nodd && cat >nodd/build.ninja <<NJ
rule bake
  command = true
  depfile = odd.d
  deps = gcc
build odd: bake
NJ
cp odd.d nodd/ && (cd nodd && ninja >/dev/null 2>&1) || flunk "ninja failed"
(cd nodd && ninja -t deps odd) | sed -n 's/^    //p' >nodd/deps
printf '%s\n' "$odd/mesh_emitter.yaml" "$odd/torus.obj" >nodd/want
cmp -s nodd/deps nodd/want || flunk "ninja read: $(cat nodd/deps)"
end
# '[' and ']' too: make globs them (a[1].png reads as a1.png where that
# exists), and a leading '~', which make expands.
for bad in $'new\nline' $'tab\there' 'glob[1]' '~tilde'; do
    begin "a depfile input with '${bad:0:3}' in its path is refused before the run"
    mkdir -p "$bad" && cp "$src/effects/mesh_emitter.yaml" "$src/effects/torus.obj" "$bad/"
    rm -f bad.csv bad.d
    pfx_run bake "$bad/mesh_emitter.yaml" --frames 0:1 -o bad.csv --depfile bad.d
    want_status 1
    stderr_has "in a depfile: make or ninja would misread its"
    [ ! -e bad.csv ] && [ ! -e bad.d ] || flunk "the bake or the depfile was written"
    end
done

summary
