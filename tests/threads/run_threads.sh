#!/usr/bin/env bash
# The simulation's thread count does not change the output, byte for byte:
# a bake and a render of a crowd of tens of thousands of particles (many
# blocks of the threaded passes) under a force set with an operator, a
# deflector with random response and on_hit births, kill rules, on_death
# births and trails, with 1, 2 and 7 threads (--threads and PFX_THREADS).
# A downpour whose hits start more particles than a block's buffer holds
# does too. A different --seed must change the bake, which shows the
# comparison can fail; a bad thread count is a usage error.
#
# usage: bash run_threads.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" threads "$@"
crowd=$src/tests/threads/crowd.yaml

for t in 1 2 7; do
    run "bake $t threads" "$pfx" bake "$crowd" -o "$work/bake_$t.csv" --threads "$t" -q
done
begin "bake: 1, 2 and 7 threads give the same bytes"
[[ -s $work/bake_1.csv ]] || flunk "no bake with 1 thread"
lines=$(wc -l <"$work/bake_1.csv")
# More particles than two blocks of 8192 in some frame, or the test shows nothing.
rows=$(awk -F, 'NR > 1 { n[$1]++ } END { m = 0; for (f in n) if (n[f] > m) m = n[f]; print m }' \
    "$work/bake_1.csv")
((rows > 20000)) || flunk "only $rows particles in the fullest frame"
for t in 2 7; do
    cmp -s "$work/bake_1.csv" "$work/bake_$t.csv" || flunk "$t threads differ from 1 ($lines lines)"
done
end

# Hits that start particles run on every thread, each block holding its
# on_hit events and the merge queueing them in pool order; the downpour
# raises more events in a block than it holds, so the merge also runs the
# rest of each block itself.
for t in 1 2 7; do
    run "downpour $t threads" "$pfx" bake "$src/tests/threads/downpour.yaml" \
        -o "$work/rain_$t.csv" --threads "$t" -q
done
begin "downpour: 1, 2 and 7 threads give the same bytes, splashes included"
splashes=$(awk -F, '$3 == "splash"' "$work/rain_1.csv" | wc -l)
((splashes > 100000)) || flunk "only $splashes splash rows"
for t in 2 7; do
    cmp -s "$work/rain_1.csv" "$work/rain_$t.csv" || flunk "$t threads differ from 1"
done
end

run "bake PFX_THREADS=3" env PFX_THREADS=3 "$pfx" bake "$crowd" -o "$work/bake_env.csv" -q
if cmp -s "$work/bake_1.csv" "$work/bake_env.csv"; then
    pass "bake: PFX_THREADS=3 gives the same bytes"
else
    fail "bake: PFX_THREADS=3 gives the same bytes"
fi

run "bake --seed 8" "$pfx" bake "$crowd" -o "$work/bake_seed.csv" --seed 8 -q
if ! cmp -s "$work/bake_1.csv" "$work/bake_seed.csv"; then
    pass "bake: another seed changes the bytes (the comparison can fail)"
else
    fail "bake: another seed changes the bytes (the comparison can fail)"
fi

for t in 1 7; do
    run "render $t threads" "$pfx" render "$crowd" -o "$work/render_$t" --size 64x64 \
        --frames 6:9 --threads "$t" -q
done
begin "render: 1 and 7 threads give the same PNGs"
for f in 6 7 8 9; do
    name=$(printf 'crowd_%04d.png' "$f")
    [[ -f $work/render_1/$name ]] || flunk "no $name"
    cmp -s "$work/render_1/$name" "$work/render_7/$name" || flunk "$name differs"
done
end

# More encoder threads than a small machine has, as a 48-core one starts:
# every one holds a temporary file while it writes (a fixed list of 16
# once failed here with "Too many open files").
begin "render: 48 threads write every frame, the same PNGs as 1"
pfx_run render "$src/effects/fire.yaml" -o "$work/render_48" --size 32x32 --frames 0:99 \
    --threads 48 -q
want_status 0
pfx_run render "$src/effects/fire.yaml" -o "$work/render_1all" --size 32x32 --frames 0:99 \
    --threads 1 -q
want_status 0
for f in $(seq 0 99); do
    name=$(printf 'fire_%04d.png' "$f")
    cmp -s "$work/render_1all/$name" "$work/render_48/$name" || flunk "$name differs or is missing"
done
end

begin "usage: --threads 0 and PFX_THREADS=x are usage errors"
pfx_run bake "$crowd" -o "$work/x.csv" --threads 0
[[ $status == 2 ]] || flunk "--threads 0: exit $status, not 2"
PFX_THREADS=x pfx_run bake "$crowd" -o "$work/x.csv"
[[ $status == 2 ]] || flunk "PFX_THREADS=x: exit $status, not 2"
end

summary
