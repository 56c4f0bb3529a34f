#!/usr/bin/env bash
# Diagnostic rule ids and `pfx validate --format sarif`: the log of broken
# effects and a clean one is checked against OASIS's SARIF 2.1.0 JSON Schema
# by python3-jsonschema (a third-party validator) and against the text
# diagnostics of the same files (check_sarif.py); a few cases against known
# answers read off the effect files (the rule, the line and column, the
# span); the rule table against the sources (every id unique and in its
# range, every rule used in src/ has a row) and against man/pfx.1.
#
#   bash run_sarif.sh PATH-TO-PFX SOURCE-DIR
set -u
source "$(dirname "${BASH_SOURCE[0]}")/../harness.sh" sarif "$@"
cd "$src" || exit 2
schema=tests/sarif/sarif-schema-2.1.0.json
D=tests/diag
BROKEN=($D/box_size_negative.yaml $D/duplicate_key.yaml $D/unknown_key_emitter.yaml
    $D/yaml_tab_indent.yaml $D/loop_warnings.yaml $D/shape_mesh_missing.yaml
    $D/yaml_unknown_alias.yaml $D/background_hash_comment.yaml $D/no_emitters_warning.yaml
    no_such_effect.yaml effects/fire.yaml)

"$pfx" validate --list-rules >"$work/rules" 2>"$work/rules.err"
begin "--list-rules"
[ $? -eq 0 ] && [ -s "$work/rules" ] && [ ! -s "$work/rules.err" ] || flunk "no rule list"
end

# sarif_case NAME STATUS FILE...: the SARIF log of FILE... exits STATUS,
# writes nothing to stderr, and agrees with the schema and the text form.
sarif_case() {
    local name=$1 want=$2
    shift 2
    begin "$name"
    pfx_run validate "$@"
    cp "$work/err" "$work/$name.text"
    pfx_run validate --format sarif "$@"
    if finished; then
        want_status "$want"
        [ ! -s "$work/err" ] || flunk "stderr: $(head -c 300 "$work/err")"
        cp "$work/out" "$work/$name.sarif"
        msg=$("$py" tests/sarif/check_sarif.py "$schema" "$work/out" "$work/rules" \
            "$work/$name.text" "$@" 2>&1) || flunk "$msg"
    fi
    end
}
sarif_case broken 1 "${BROKEN[@]}"
sarif_case clean 0 effects/fire.yaml
sarif_case warnings-only 0 $D/loop_warnings.yaml

# Known answers, from the effect files themselves: the rule (by name, through
# the driver's table), line, column and end column of the first result of
# each file, and the note of the duplicate key.
begin "known answers"
msg=$("$py" - "$work/broken.sarif" <<'PY' 2>&1
import json, sys
run = json.load(open(sys.argv[1]))["runs"][0]
rules = run["tool"]["driver"]["rules"]
first = {}
for r in run["results"]:
    locs = r.get("locations") or [{}]
    uri = locs[0].get("physicalLocation", {}).get("artifactLocation", {}).get("uri")
    first.setdefault(uri, r)
D = "tests/diag/"
# file: (rule name, id, level, (line, column, end column) or None)
want = {
    D + "box_size_negative.yaml": ("out-of-range", "PFX3001", "error", (5, 35, 37)),   # -1
    D + "duplicate_key.yaml": ("duplicate-key", "PFX2002", "error", (7, 5, 9)),         # rate
    D + "unknown_key_emitter.yaml": ("unknown-key", "PFX2001", "error", (6, 5, 12)),    # lifetme
    D + "yaml_tab_indent.yaml": ("yaml-syntax", "PFX1001", "error", (5, 1, 2)),
    D + "loop_warnings.yaml": ("loop-seam", "PFX5002", "warning", (6, 37, 38)),
    D + "shape_mesh_missing.yaml": ("missing-file", "PFX4002", "error", (5, 32, 48)),   # no_such_mesh.obj
    D + "yaml_unknown_alias.yaml": ("unknown-anchor", "PFX1004", "error", (5, 12, 17)), # *fast
    D + "no_emitters_warning.yaml": ("empty-effect", "PFX5005", "warning", (2, 1, 2)),
    "no_such_effect.yaml": ("missing-file", "PFX4002", "error", None),
}
bad = []
for uri, (name, rid, level, pos) in want.items():
    r = first.get(uri)
    if r is None:
        bad.append(f"no result for {uri}")
        continue
    rule = rules[r["ruleIndex"]]
    region = r["locations"][0]["physicalLocation"].get("region")
    got_pos = (region["startLine"], region["startColumn"], region["endColumn"]) if region else None
    if (rule["name"], r["ruleId"], rule["id"], r["level"], got_pos) != (name, rid, rid, level, pos):
        bad.append(f"{uri}: {rule['name']} {r['ruleId']} {r['level']} {got_pos}, "
                   f"expected {name} {rid} {level} {pos}")
dup = first.get(D + "duplicate_key.yaml", {}).get("relatedLocations", [])
if [(n["physicalLocation"]["region"]["startLine"], n["physicalLocation"]["region"]["startColumn"],
     n["message"]["text"]) for n in dup] != [(5, 5, "'rate' first defined here")]:
    bad.append(f"duplicate key's note: {dup}")
clean = [r for r in run["results"]
         if r.get("locations") and r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
         == "effects/fire.yaml"]
if clean:
    bad.append(f"effects/fire.yaml has results: {clean[:1]}")
print("\n".join(bad))
sys.exit(1 if bad else 0)
PY
) || flunk "$msg"
end

# A path with a space, given absolute: a file: URI, percent-encoded.
begin "absolute path with a space"
mkdir -p "$work/a dir"
cp $D/box_size_negative.yaml "$work/a dir/b x.yaml"
pfx_run validate --format sarif "$work/a dir/b x.yaml"
want_status 1
"$py" -c '
import json, sys, urllib.parse
r = json.load(open(sys.argv[1]))["runs"][0]["results"][0]
uri = r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
want = "file://" + urllib.parse.quote(sys.argv[2])
sys.exit(0 if uri == want and " " not in uri else f"uri {uri!r}, expected {want!r}")
' "$work/out" "$work/a dir/b x.yaml" || flunk "bad uri"
end

# An absolute path inside the current directory: relative to %SRCROOT%,
# which the run sets to the current directory (code scanning resolves
# artifact URIs against it); the log still meets the schema.
begin "absolute path inside the current directory: relative to %SRCROOT%"
pfx_run validate --format sarif "$src/$D/box_size_negative.yaml"
want_status 1
msg=$("$py" - "$work/out" "$schema" "$(pwd -P)" <<'PY' 2>&1
import json, sys, urllib.parse, jsonschema
log = json.load(open(sys.argv[1]))
schema = json.load(open(sys.argv[2]))
jsonschema.validators.validator_for(schema)(schema).validate(log)
run = log["runs"][0]
base = run.get("originalUriBaseIds", {}).get("%SRCROOT%", {}).get("uri")
want = "file://" + urllib.parse.quote(sys.argv[3]) + "/"
loc = run["results"][0]["locations"][0]["physicalLocation"]["artifactLocation"]
bad = []
if base != want:
    bad.append(f"%SRCROOT% {base!r}, expected {want!r}")
if loc != {"uri": "tests/diag/box_size_negative.yaml", "uriBaseId": "%SRCROOT%"}:
    bad.append(f"artifactLocation {loc}")
print("\n".join(bad))
sys.exit(1 if bad else 0)
PY
) || flunk "$msg"
end

# allow: an acknowledged warning is a result with a suppression carrying the
# file's reason, and the log exits 0 with --werror.
begin "allowed warning: a suppression with its justification"
pfx_run validate --format sarif --werror $D/allow_loop_seam.yaml
want_status 0
[ ! -s "$work/err" ] || flunk "stderr: $(head -c 300 "$work/err")"
msg=$("$py" - "$work/out" "$schema" <<'PY' 2>&1
import json, sys, jsonschema
log = json.load(open(sys.argv[1]))
schema = json.load(open(sys.argv[2]))
jsonschema.validators.validator_for(schema)(schema).validate(log)
res = log["runs"][0]["results"]
got = [(r["ruleId"], r["level"], r["locations"][0]["physicalLocation"]["region"]["startLine"],
        r.get("suppressions")) for r in res]
want = [("PFX5002", "warning", 11,
         [{"kind": "inSource", "justification": "the splash counts differ per loop"}])]
sys.exit(0 if got == want else f"results {got}, expected {want}")
PY
) || flunk "$msg"
end

# The exit status is that of the text form: --werror fails on a warning.
begin "--werror"
pfx_run validate --format sarif --werror $D/loop_warnings.yaml
want_status 1
"$py" -c 'import json,sys; json.load(open(sys.argv[1]))' "$work/out" || flunk "no log on stdout"
grep -qF "treated as error" "$work/err" || flunk "no --werror line on stderr"
end

# A log that cannot be written is an error, not a silent exit 0.
begin "full standard output"
if [ -w /dev/full ]; then
    (exec "$pfx" validate --format sarif effects/fire.yaml >/dev/full 2>"$work/full.err")
    status=$?
    want_status 1
    grep -qF "cannot write the SARIF log" "$work/full.err" || flunk "no error: $(cat "$work/full.err")"
fi
end

begin "usage errors"
pfx_run render --format sarif effects/fire.yaml -o "$work/r"
want_status 2
pfx_run bake --list-rules effects/fire.yaml -o "$work/b.csv"
want_status 2
pfx_run validate --format xml effects/fire.yaml
want_status 2
grep -qF "'text', 'json' or 'sarif'" "$work/err" || flunk "the usage error does not list sarif"
end

# The table: ids unique, each in the range its comment gives it, names
# unique kebab-case, help one sentence; every PFX_RULE_ used in src/ has a
# row and every row is used (or marked retired).
begin "rule table"
msg=$("$py" - src <<'PY' 2>&1
import os, re, sys
# The rows without the macro's line continuations.
text = re.sub(r"\\\n", "\n", open("src/base/diag_rules.h").read())
rows = re.findall(r'X\((\d+),\s*(\w+),\s*"([^"]*)",\s*(\w+),\s*((?:"(?:[^"\\]|\\.)*"\s*)+)\)', text)
bad = []
ids = [int(r[0]) for r in rows]
if len(rows) < 30 or len(set(ids)) != len(ids):
    bad.append(f"{len(rows)} rows, ids not unique: {sorted(i for i in ids if ids.count(i) > 1)}")
if ids != sorted(ids):
    bad.append("rows are not in id order")
for num, ident, name, sev, help_parts in rows:
    if not re.fullmatch(r"[a-z][a-z0-9]*(-[a-z0-9]+)*", name) or ident != name.upper().replace("-", "_"):
        bad.append(f"{num}: name {name!r} / {ident}")
    if int(num) // 1000 not in (1, 2, 3, 4, 5, 6, 9) or sev not in ("ERROR", "WARNING"):
        bad.append(f"{num}: outside the ranges or severity {sev}")
    if int(num) // 1000 == 5 and sev != "WARNING":
        bad.append(f"{num}: a 5xxx rule is a warning")
names = [r[2] for r in rows]
if len(set(names)) != len(names):
    bad.append("names not unique")
used = set()
for d, _, fs in os.walk("src"):
    for f in fs:
        if f.endswith((".c", ".h")) and f != "diag_rules.h":
            used |= set(re.findall(r"\bPFX_RULE_([A-Z0-9_]+)\b", open(os.path.join(d, f)).read()))
used -= {"NONE", "ENUM", "ROW"}
known = {r[1] for r in rows}
if used - known:
    bad.append(f"used without a row: {sorted(used - known)}")
unused = [r[1] for r in rows if r[1] not in used and "(retired)" not in r[4]]
if unused:
    bad.append(f"rows no call site uses: {unused}")
print("\n".join(bad))
sys.exit(1 if bad else 0)
PY
) || flunk "$msg"
end

begin "man page lists the rules"
msg=$("$py" tests/sarif/man_rules.py "$work/rules" man/pfx.1 2>&1) || flunk "$msg"
end

summary
