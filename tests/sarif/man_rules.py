#!/usr/bin/python3
"""The rule list of man/pfx.1 against `pfx validate --list-rules`.

    man_rules.py RULES MAN            exit 0 when the page lists exactly the
                                      rules (same ids, names, severities and
                                      help, same order); else say why, exit 1
    man_rules.py --update RULES MAN   rewrite the list between the page's
                                      BEGIN RULES and END RULES comments

RULES is the output of `pfx validate --list-rules`: a line per rule, id,
severity, name and help separated by runs of spaces. Standard library only.
"""
import re
import sys
import textwrap

from rule_list import read_rules

update = sys.argv[1] == "--update"
rules_path, man_path = sys.argv[2:4] if update else sys.argv[1:3]
rules = read_rules(rules_path)
if not rules:
    sys.exit("--list-rules printed no rules")


def roff(text):
    return text.replace("\\", "\\e").replace("-", "\\-")


def lines(text):
    """Text lines of at most 80 bytes (mandoc's style limit); a line that
    would start with a roff control character is guarded with \\&."""
    out = textwrap.wrap(text, 76, break_on_hyphens=False)
    return ["\\&" + l if l[0] in ".'" else l for l in out]


block = []
for rid, sev, name, help_text in rules:
    block += [".TP", f".BR {rid} \" {roff(name)}\""] + lines(f"({sev}) {roff(help_text)}")
page = open(man_path, encoding="utf-8").read()
m = re.search(r"^(\.\\\" BEGIN RULES[^\n]*\n)(.*?)(^\.\\\" END RULES)", page, re.S | re.M)
if not m:
    sys.exit(f"{man_path} has no BEGIN RULES ... END RULES comments")
want = "\n".join(block) + "\n"
if update:
    page = page[: m.start(2)] + want + page[m.end(2):]
    open(man_path, "w", encoding="utf-8").write(page)
elif m.group(2) != want:
    got = m.group(2).splitlines()
    for i, (a, b) in enumerate(zip(got + [""] * len(block), block + [""] * len(got))):
        if a != b:
            sys.exit(f"{man_path}: the rule list differs from --list-rules at its line {i + 1}:\n"
                     f"  page: {a!r}\n  pfx:  {b!r}\n(run tests/sarif/man_rules.py --update)")
