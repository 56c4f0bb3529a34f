#!/bin/bash
# Builds pfx with AddressSanitizer and UndefinedBehaviorSanitizer in its own
# tree (with the renderers of the main build: CMAKE-ARGS) and runs the unit,
# CLI and diagnostics tests under them. Leaks inside Mesa's libOSMesa (a few
# hundred bytes per context, none per frame) are suppressed; every other
# leak or UB report fails the run.
#
#   bash sanitize.sh PATH-TO-PFX SOURCE-DIR [CMAKE-ARGS...]
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" sanitize "$@"
shift 2
tree=$pfx_dir/sanitize-tree
supp=$tree/lsan.supp
mkdir -p "$tree"
printf 'leak:libOSMesa.so\nleak:libLLVM\nleak:libgallium\nleak:swrast_dri\n' >"$supp"

if ! run configure cmake -S "$src" -B "$tree" -DPFX_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@"; then
    fail "configure the sanitizer tree $tree"
    summary
    exit
fi
pass "configure the sanitizer tree"
if ! run build cmake --build "$tree" -j2; then
    tail -30 "$work/build.out"
    fail "build the sanitizer tree"
    summary
    exit
fi
pass "build the sanitizer tree"

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0
export LSAN_OPTIONS="suppressions=$supp:print_suppressions=0"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export PFX_TEST_QUICK=1
# --no-tests=error: a label that matched nothing would otherwise pass. The
# ~200 tests (one per diagnostics case) run on every core; in a serial
# ctest run this test runs alone, so the cores are free.
if ctest --test-dir "$tree" -L 'unit|cli|diag' -j "$(nproc)" --no-tests=error --output-on-failure; then
    pass "the unit, cli and diag tests under ASan and UBSan"
else
    fail "the unit, cli and diag tests under ASan and UBSan"
fi
summary
