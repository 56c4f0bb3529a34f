#!/usr/bin/python3
"""The --format json form of a diagnostics run against its text form.

    check_json.py TEXT_STDERR JSON_STDERR FILE

Every JSON line is an object with exactly file, line, column, severity, rule
and message, in valid UTF-8, and the objects are the text diagnostics (their
`FILE:LINE:COL: severity: message [PFXnnnn]` headers) in the same order. Every
error and warning names a rule (PFX and four digits), the one its text line
ends with; a note names none (null) and its text line ends with no id. Exits 0 when
they agree; otherwise prints why and exits 1. Standard library only.
"""
import json
import re
import sys

text_path, json_path, file = sys.argv[1:4]
raw = open(json_path, "rb").read()
try:
    lines = raw.decode("utf-8").splitlines()
except UnicodeDecodeError as e:
    sys.exit(f"--format json output is not UTF-8: {e}")
got = []
for i, line in enumerate(lines, 1):
    try:
        o = json.loads(line)
    except ValueError as e:
        sys.exit(f"json line {i} does not parse ({e}): {line[:200]!r}")
    if not isinstance(o, dict) or set(o) != {"file", "line", "column", "severity", "rule", "message"}:
        sys.exit(f"json line {i} is not an object with file, line, column, severity, rule, message: {line[:200]!r}")
    rule_ok = o["rule"] is None if o["severity"] == "note" else \
        isinstance(o["rule"], str) and re.fullmatch(r"PFX\d{4}", o["rule"])
    if not rule_ok:
        sys.exit(f"json line {i} has a bad rule for a {o['severity']}: {line[:200]!r}")
    if o["file"] != file or not isinstance(o["line"], int) or not isinstance(o["column"], int) \
            or o["severity"] not in ("error", "warning", "note") or not isinstance(o["message"], str):
        sys.exit(f"json line {i} has a bad field: {line[:200]!r}")
    got.append((o["line"], o["column"], o["severity"], o["rule"], o["message"]))
# The text form's headers, in order (the "N more not shown" note has no JSON twin).
head = re.compile(r"^(.*?)(?::(\d+):(\d+))?: (error|warning|note): (.*?)(?: \[(PFX\d{4})\])?$")
want = []
for line in open(text_path, "rb").read().decode("utf-8", "replace").splitlines():
    if line.startswith(file + ":") or line.startswith(file + ": "):
        m = head.match(line)
        if m and m.group(1) == file and not re.fullmatch(r"\d+ more diagnostics not shown", m.group(5)):
            want.append((int(m.group(2) or 0), int(m.group(3) or 0), m.group(4), m.group(6), m.group(5)))
if got != want:
    sys.exit(f"json diagnostics differ from the text ones:\n  json: {got[:5]}\n  text: {want[:5]}")
