#!/bin/bash
# Builds pfx with AddressSanitizer and UndefinedBehaviorSanitizer in its own
# tree (with the renderers of the main build: CMAKE-ARGS) and runs the unit,
# CLI and diagnostics tests under them. Leaks inside Mesa's libOSMesa (a few
# hundred bytes per context, none per frame) are suppressed; every other
# leak or UB report fails the run.
#   bash sanitize.sh PATH-TO-PFX SOURCE-DIR [CMAKE-ARGS...]
set -u
pfx=$1
src=$2
shift 2
bin_dir=$(cd "$(dirname "$pfx")" && pwd)
tree="$bin_dir/sanitize-tree"
supp="$tree/lsan.supp"
mkdir -p "$tree"
printf 'leak:libOSMesa.so\nleak:libLLVM\nleak:libgallium\nleak:swrast_dri\n' > "$supp"
cmake -S "$src" -B "$tree" -DPFX_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@" >/dev/null || exit 1
cmake --build "$tree" -j2 >/dev/null || { cmake --build "$tree" 2>&1 | tail -30; exit 1; }
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0
export LSAN_OPTIONS="suppressions=$supp:print_suppressions=0"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export PFX_TEST_QUICK=1
ctest --test-dir "$tree" -L 'unit|cli|diag' --output-on-failure
