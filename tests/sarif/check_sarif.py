#!/usr/bin/python3
"""A `pfx validate --format sarif` log against the SARIF 2.1.0 schema and
against the text diagnostics of the same files.

    check_sarif.py SCHEMA LOG RULES TEXT_STDERR FILE...

SCHEMA is OASIS's sarif-schema-2.1.0.json, checked with python3-jsonschema
(a validator pfx has no part in), formats included. RULES is the output of
`pfx validate --list-rules`; TEXT_STDERR the stderr of `pfx validate FILE...`
in text form. Checks that the log has one run whose driver is pfx with
exactly the listed rules, and that its results are the text diagnostics in
order: ruleId = the [PFXnnnn] of the text line, ruleIndex pointing at that
rule, level = severity, message, uri = FILE as given, startLine and
startColumn = the text's LINE:COL, and each note a related location of the
result before it. Exits 0 when all hold; else prints why and exits 1.
"""
import json
import re
import sys

import jsonschema

from rule_list import read_rules

schema_path, log_path, rules_path, text_path, *files = sys.argv[1:]
schema = json.load(open(schema_path, encoding="utf-8"))
raw = open(log_path, "rb").read()
try:
    log = json.loads(raw.decode("utf-8"))
except (UnicodeDecodeError, ValueError) as e:
    sys.exit(f"the log is not UTF-8 JSON: {e}")
cls = jsonschema.validators.validator_for(schema)
cls.check_schema(schema)
errors = sorted(cls(schema, format_checker=jsonschema.FormatChecker()).iter_errors(log),
                key=lambda e: list(e.absolute_path))
if errors:
    sys.exit("the log breaks the SARIF 2.1.0 schema:\n" + "\n".join(
        f"  at /{'/'.join(map(str, e.absolute_path))}: {e.message[:200]}" for e in errors[:10]))

bad = []
if log.get("version") != "2.1.0" or len(log.get("runs", [])) != 1:
    bad.append(f"version {log.get('version')!r}, {len(log.get('runs', []))} runs")
run = log["runs"][0]
driver = run["tool"]["driver"]
if driver.get("name") != "pfx" or not driver.get("version"):
    bad.append(f"driver {driver.get('name')!r} {driver.get('version')!r}")

# The rules: exactly --list-rules, in its order.
listed = read_rules(rules_path)
rules = driver.get("rules", [])
got_rules = [(r["id"], r["defaultConfiguration"]["level"], r["name"], r["shortDescription"]["text"])
             for r in rules]
if got_rules != listed:
    bad.append(f"driver.rules differ from --list-rules: {got_rules[:3]} vs {listed[:3]}")

# The text headers: FILE:LINE:COL: severity: message [PFXnnnn], and
# FILE: severity: message [PFXnnnn] for a problem with no place.
head = re.compile(r"^(.*?)(?::(\d+):(\d+))?: (error|warning|note): (.*?)(?: \[(PFX\d{4})\])?$")
want = []
for line in open(text_path, encoding="utf-8", errors="replace").read().splitlines():
    m = head.match(line)
    if m and m.group(1) in files:
        f, l, c, sev, msg, rid = m.groups()
        want.append((f, int(l or 0), int(c or 0), sev, msg, rid))


def uri_of(path):
    return path if not path.startswith("/") else "file://" + path


got = []
for k, r in enumerate(run["results"]):
    loc = r["locations"][0]["physicalLocation"] if r.get("locations") else None
    region = loc.get("region", {}) if loc else {}
    f = loc["artifactLocation"]["uri"] if loc else None
    rid = r.get("ruleId")
    if rid is not None and rules[r["ruleIndex"]]["id"] != rid:
        bad.append(f"result {k}: ruleIndex {r['ruleIndex']} is {rules[r['ruleIndex']]['id']}, not {rid}")
    if region and region["endColumn"] <= region["startColumn"]:
        bad.append(f"result {k}: empty region {region}")
    got.append((f, region.get("startLine", 0), region.get("startColumn", 0), r["level"],
                r["message"]["text"], rid))
    for n in r.get("relatedLocations", []):
        nl = n.get("physicalLocation", {})
        nr = nl.get("region", {})
        got.append((nl.get("artifactLocation", {}).get("uri"), nr.get("startLine", 0),
                    nr.get("startColumn", 0), "note", n["message"]["text"], None))
want = [(uri_of(f), l, c, sev, msg, rid) for f, l, c, sev, msg, rid in want]
if got != want:
    for i, (g, w) in enumerate(zip(got + [None] * len(want), want + [None] * len(got))):
        if g != w:
            bad.append(f"result {i} differs from the text diagnostics:\n    sarif: {g}\n    text:  {w}")
            break
if bad:
    sys.exit("\n".join(bad))
