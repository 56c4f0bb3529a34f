#!/bin/sh
# The latency of pfx preview, per example: milliseconds from saving an
# effect file to the new frame under the playhead (mid-effect) drawn in a
# headless Chromium, at 512x512, the median of five saves, and the CPU
# time pfx spent on each (a loaded machine stretches the first, not the
# second). A benchmark, not a test: nothing is asserted.
#   tools/bench_preview.sh [BUILD/pfx] [EFFECT.yaml...]   (default: effects/*.yaml)
# Needs chromium, chromium-driver and python3-selenium (install-deps --test).
set -eu
src=$(cd "$(dirname "$0")/.." && pwd)
pfx=$(realpath "${1:-$src/build/pfx}")
[ $# -gt 0 ] && shift
[ $# -gt 0 ] || set -- "$src"/effects/*.yaml
work=$(mktemp -d "${TMPDIR:-/tmp}/pfx-bench-preview.XXXXXX")
trap 'rm -rf "$work"' EXIT
/usr/bin/python3 "$src/tests/preview/check_browser.py" "$pfx" "$src" "$work" --bench "$@"
