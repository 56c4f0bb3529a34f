"""The output of `pfx validate --list-rules`, read: a line per rule, id,
severity, name and help separated by runs of spaces. Shared by
check_sarif.py and man_rules.py. Standard library only."""
import re
import sys


def read_rules(path):
    """[(id, severity, name, help), ...] in the listed order; exits with the
    line when one does not parse."""
    rules = []
    for line in open(path, encoding="utf-8").read().splitlines():
        m = re.fullmatch(r"(PFX\d{4})  +(error|warning|note)  +([a-z0-9-]+)  +(\S.*)", line)
        if not m:
            sys.exit(f"--list-rules line does not parse: {line!r}")
        rules.append(m.groups())
    return rules
