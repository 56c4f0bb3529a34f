#!/usr/bin/env bash
# Help: `pfx --help` prints every command and option; `pfx COMMAND --help`
# (or -h, or `pfx help COMMAND`) prints that command's usage and the options
# it takes and no other, on stdout with exit 0 and nothing on stderr. Both
# come from one table of options in src/main.c, so a command's options are
# checked here against what it is documented to take, and against the full
# help.
#
#   bash run_help.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" help "$@"

# The long options of the last run's stdout, one a line.
long_options() { grep -oE -- '--[a-z][a-z0-9-]*' "$work/out" | sort -u; }

# help_lists CMD "OPTION..." "OPTION...": `pfx CMD --help` succeeds, starts
# with its usage, and lists the first options and none of the second.
help_lists() {
    local cmd=$1 want=$2 never=$3 o
    begin "pfx $cmd --help: its usage and its options only"
    pfx_run "$cmd" --help
    if finished; then
        want_status 0
        stderr_empty
        [ "$(head -n 1 "$work/out" | cut -d' ' -f1-3)" = "usage: pfx $cmd" ] ||
            flunk "the first line is '$(head -n 1 "$work/out")'"
        grep -q "^usage: pfx $cmd\|^       pfx $cmd" "$work/out" || flunk "no usage line"
        grep -E '^(usage:|       )pfx ' "$work/out" | grep -v "pfx $cmd" | grep -q . &&
            flunk "another command's usage: $(grep -E '^(usage:|       )pfx ' "$work/out" | grep -v "pfx $cmd")"
        grep -q '^commands:' "$work/out" && flunk "the list of commands"
        for o in $want; do
            grep -qE -- "^  (-[a-z], |    )$o([ =[]|$)" "$work/out" || flunk "no row for $o"
        done
        for o in $never; do
            grep -qE -- "(^| |\[)$o([ =[]|$)" "$work/out" && flunk "lists $o"
        done
    fi
    end
}

help_lists validate "--format --werror --max-particles --max-memory --list-rules --help" \
    "--atlas --every --jobs --slice --renderer --output"
help_lists render "--output --jobs --keep-going --frames --size --fps --seed --max-particles
    --max-memory --renderer --alpha --threads --force --depfile --progress --atlas --padding
    --extrude --crop --preview --format --quiet --motion-vectors --mv-max --mv-flip-y --slice
    --slice-env --slice-count --help" "--every --list-rules --werror --json --version"
help_lists bake "--output --format --every --frames --fps --seed --max-particles --max-memory
    --threads --force --depfile --quiet --help" \
    "--atlas --preview --jobs --slice --renderer --alpha --list-rules --motion-vectors --size"
help_lists info "--format --seed --max-particles --max-memory --threads --motion-vectors --help" \
    "--output --atlas --every --jobs --slice --renderer"
help_lists bench "--json --renderer --output --help" "--atlas --every --frames --slice --format"
help_lists assemble "--output --atlas --preview --padding --extrude --crop --help" \
    "--frames --every --slice --renderer --format --jobs"
help_lists schema "--help" "--output --format --frames --quiet"

begin "-h, --help and 'pfx help COMMAND' print the same"
for cmd in validate render bake info bench assemble schema; do
    pfx_run "$cmd" --help
    cp "$work/out" "$work/long"
    pfx_run "$cmd" -h
    want_status 0
    cmp -s "$work/out" "$work/long" || flunk "$cmd -h differs from $cmd --help"
    pfx_run help "$cmd"
    want_status 0
    cmp -s "$work/out" "$work/long" || flunk "help $cmd differs from $cmd --help"
    # Among the other words: the help wins and nothing runs.
    pfx_run "$cmd" "$src/effects/fire.yaml" -o "$work/nothing" --help
    want_status 0
    cmp -s "$work/out" "$work/long" || flunk "$cmd FILE -o DIR --help differs"
done
[ ! -e "$work/nothing" ] || flunk "'--help' among a command's words wrote '$work/nothing'"
end

begin "pfx --help: every command's usage, the commands and every option"
pfx_run --help
if finished; then
    want_status 0
    stderr_empty
    cp "$work/out" "$work/full"
    for cmd in validate render bake info bench assemble schema; do
        grep -qE "^  $cmd +[a-z]" "$work/full" || flunk "no line for $cmd under commands"
        pfx_run "$cmd" --help
        # The command's usage and option rows, as they stand in the full help.
        sed -n '/^options:/,$p' "$work/out" | tail -n +2 >"$work/rows"
        grep -vxFf "$work/full" "$work/rows" | grep -q . && flunk "$cmd --help has rows the full help lacks"
        sed -n '/^$/q;p' "$work/out" | sed 's/^usage: /       /' >"$work/usage"
        sed 's/^usage: /       /' "$work/full" | grep -vxFf - "$work/usage" | grep -q . &&
            flunk "$cmd's usage is not in the full help"
    done
    grep -q -- '--version' "$work/full" || flunk "no --version"
fi
end

begin "pfx help nosuch: a usage error"
pfx_run help rendr
want_status 2
stdout_empty
stderr_has "pfx: unknown command 'rendr'; did you mean 'render'?"
end

summary
