#!/usr/bin/python3
"""Writes a libFuzzer dictionary for the effect format to stdout, from the
JSON Schema that `pfx schema` prints on stdin (generated from the
compiler's key tables, so a new key reaches the fuzzer with no edit here):
every property name as a YAML key, every enum and const string as a value,
and the YAML punctuation and number spellings that reach the readers'
corners."""
import json
import sys


def walk(node, keys, values):
    if isinstance(node, dict):
        for name, sub in node.get("properties", {}).items():
            keys.add(name)
            walk(sub, keys, values)
        for word in ("enum", "const"):
            v = node.get(word)
            for item in v if isinstance(v, list) else [v]:
                if isinstance(item, str):
                    values.add(item)
        for name, sub in node.items():
            if name != "properties":
                walk(sub, keys, values)
    elif isinstance(node, list):
        for sub in node:
            walk(sub, keys, values)


def quote(text):
    return '"' + "".join(c if 32 <= ord(c) < 127 and c not in '"\\' else "\\x%02x" % ord(c)
                         for c in text) + '"'


def main():
    schema = json.load(sys.stdin)
    keys, values = set(), set()
    walk(schema, keys, values)
    words = {k + ": " for k in keys} | values
    words |= {"pfx: 1\n", "emitters:\n  ", "\n    ", "{", "}", "[", "]", ", ", "- ", "&a ",
              "*a", "<<: ", "!!str ", "---\n", "...\n", "'", "\"", "#", "~", "null", "true",
              "1e400", "-1e-400", ".nan", ".inf", "-.inf", "0x1p3", "-0", "1e9", "18446744073709551616",
              "#ff8020", "#40000000", "{ t: 0, value: 1 }", "{ at: 0.5, value: 1 }",
              "{ emit: a, count: 100000, depth: 16 }", "v 0 0 0\n", "f 1 2 3\n"}
    for i, w in enumerate(sorted(words)):
        print("w%d=%s" % (i, quote(w)))


if __name__ == "__main__":
    main()
