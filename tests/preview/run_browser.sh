# pfx preview's page in headless Chromium (check_browser.py): frame K as
# pfx render draws it, live reload of colours and typos, stepping,
# scrubbing, tracks, pick, A/B, and the save-to-frame latency (printed, not
# asserted: a benchmark, tools/bench_preview.sh, reports it per example).
# Skips (77) where chromium, chromedriver or python3-selenium is missing.
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" preview_browser "$@"
if [ ! -x /usr/bin/chromium ] || [ ! -x /usr/bin/chromedriver ] ||
   ! "$py" -c 'import selenium' 2>/dev/null; then
    echo "skipped: needs chromium, chromium-driver and python3-selenium (install-deps --test)"
    exit 77
fi
tally "$("$py" "$src/tests/preview/check_browser.py" "$pfx" "$src" "$work" \
    ${PFX_SCREENSHOT:+--screenshot "$PFX_SCREENSHOT"} 2>&1)"
summary
