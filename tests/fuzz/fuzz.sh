#!/usr/bin/env bash
# The libFuzzer targets of tests/fuzz under AddressSanitizer and
# UndefinedBehaviorSanitizer, for CTest (label fuzz) and by hand:
#
#   bash fuzz.sh PFX SOURCE-DIR build           configure and build the fuzz
#       tree beside PFX (clang, PFX_FUZZ, PFX_SANITIZE) and the dictionary
#       from `PFX schema`; exit 77 (CTest's skip) with a SKIP line when
#       clang or its libFuzzer runtime is missing
#   bash fuzz.sh PFX SOURCE-DIR run TARGET      run fuzz_TARGET for
#       $PFX_FUZZ_SECONDS (default 60) from the seed corpus; a crash, a
#       sanitizer report, a leak, an input slower than 10 s or a process
#       above 2 GB is a failure, saved under the tree's findings/
#
# Seeds: effects/*.yaml and tests/diag/*.yaml for the effect targets, the
# OBJ files of effects/ and tests/diag for fuzz_obj, the PNG textures of
# effects/textures and tests/diag for fuzz_png, tests/fuzz/jobs/*.seed
# (crafted slice folders) for fuzz_jobs, and for fuzz_lsp whole LSP
# sessions on the examples (tests/fuzz/lsp_seeds.py). A long campaign is in
# tests/fuzz/README.
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" fuzz "$@"
mode=${3-}
tree=$pfx_dir/fuzz-tree
supp=$tree/lsan.supp

skip() {
    echo "SKIP: $1"
    exit 77
}

# libFuzzer ships with clang (Debian: clang and libclang-rt-dev); a program
# that links with -fsanitize=fuzzer proves both are there.
have_libfuzzer() {
    command -v clang >/dev/null 2>&1 || return 1
    printf 'int LLVMFuzzerTestOneInput(const char *d, unsigned long n) { (void)d; (void)n; return 0; }\n' \
        >"$work/probe.c"
    clang -fsanitize=fuzzer,address,undefined "$work/probe.c" -o "$work/probe" >"$work/probe.log" 2>&1
}

build() {
    have_libfuzzer || skip "clang with libFuzzer is not installed (./install-deps --test installs clang and libclang-rt-dev)"
    mkdir -p "$tree"
    if ! run configure env CC=clang cmake -S "$src" -B "$tree" -DPFX_FUZZ=ON -DPFX_SANITIZE=ON \
        -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBUILD_TESTING=OFF; then
        fail "configure the fuzz tree $tree"
        return
    fi
    local targets
    targets=$(cd "$src/tests/fuzz" && ls fuzz_*.c | sed 's/\.c$//')
    # shellcheck disable=SC2086
    if ! run build cmake --build "$tree" -j "$(nproc)" --target $targets; then
        tail -30 "$work/build.out"
        fail "build the fuzz targets"
        return
    fi
    pass "build the fuzz targets: $(echo $targets)"
    if "$pfx" schema | "$py" "$src/tests/fuzz/dict.py" >"$tree/pfx.dict" && [ -s "$tree/pfx.dict" ]; then
        pass "the dictionary from pfx schema: $(grep -c . "$tree/pfx.dict") words"
    else
        fail "the dictionary from pfx schema"
    fi
    # Mesa keeps a few hundred bytes per context for the process's life.
    printf 'leak:libOSMesa.so\nleak:libLLVM\nleak:libgallium\nleak:swrast_dri\nleak:libEGL\nleak:libGLX\n' >"$supp"
}

fuzz_run() {
    local target=$1 seconds=${PFX_FUZZ_SECONDS:-60} exe=$tree/tests/fuzz/fuzz_$1 corpus seeds
    [ -x "$exe" ] || {
        have_libfuzzer || skip "clang with libFuzzer is not installed"
        fail "no $exe: run the fuzz/build test first"
        return
    }
    corpus=$work/corpus
    seeds=$work/seeds
    mkdir -p "$corpus" "$seeds" "$tree/findings"
    case $target in
    obj) cp "$src"/effects/*.obj "$src"/tests/diag/*.obj "$seeds/" ;;
    png) cp "$src"/effects/textures/*.png "$src"/tests/diag/*.png "$seeds/" ;;
    set) # --set words, one a line, for fuzz_set.c's fixed effect
        printf '%s\n' emitters.flame.rate=300 sim.integrator=rk4 >"$seeds/replace-insert"
        printf '%s\n' 'emitters.copy.color.1=#ff0000' 'emitters.flame.size={start: 1}' >"$seeds/item-map"
        printf '%s\n' emitters.flam.rate=1 emitters.flame.shape.radiu=2 >"$seeds/typos"
        ;;
    jobs) cp "$src"/tests/fuzz/jobs/*.seed "$seeds/" ;;
    lsp) "$py" "$src/tests/fuzz/lsp_seeds.py" "$src" "$seeds" ;; # whole sessions
    *) cp "$src"/effects/*.yaml "$src"/tests/diag/*.yaml "$seeds/" ;;
    esac
    local args=(-dict="$tree/pfx.dict" -max_len=65536)
    [ "$target" = obj ] && args=(-max_len=65536)
    [ "$target" = png ] && args=(-max_len=65536)
    [ "$target" = jobs ] && args=(-max_len=65536)
    [ "$target" = sim ] && args=(-dict="$tree/pfx.dict" -max_len=16384)
    echo "fuzz_$target for $seconds s: $exe ${args[*]} CORPUS SEEDS"
    ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 \
        LSAN_OPTIONS="suppressions=$supp:print_suppressions=0" \
        UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
        timeout $((seconds + 120)) "$exe" "${args[@]}" -max_total_time="$seconds" -timeout=10 \
        -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$tree/findings/$target-" \
        "$corpus" "$seeds" >"$work/fuzz.log" 2>&1
    local rc=$? runs
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/fuzz.log" | tail -1)
    if [ "$rc" -eq 0 ] && [ -n "$runs" ]; then
        pass "fuzz_$target: $runs executions in $seconds s, no finding"
    else
        tail -60 "$work/fuzz.log"
        fail "fuzz_$target: exit status $rc; the input is under $tree/findings/ (reproduce: $exe FILE)"
    fi
}

case $mode in
build) build ;;
run) fuzz_run "${4-}" ;;
*)
    echo "usage: bash fuzz.sh PATH-TO-PFX SOURCE-DIR build|run TARGET" >&2
    exit 2
    ;;
esac
summary
