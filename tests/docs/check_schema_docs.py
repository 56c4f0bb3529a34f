"""The schema's annotations, for editors that stay with yaml-language-server:
every key's property carries its own meaning (title, description and
markdownDescription that start with it, the text pfx lsp's hover shows),
the forms' descriptions after it, and every colour form carries the colour's
error message. Prints `ok   NAME` / `FAIL NAME` lines for harness.sh's tally.

    python3 check_schema_docs.py PATH-TO-PFX SOURCE-DIR
"""
import json
import os
import subprocess
import sys

pfx, src = sys.argv[1], sys.argv[2]
sys.path.insert(0, os.path.join(src, "tests", "lsp"))
from lsp_client import Client  # noqa: E402

failures = 0


def check(name, ok, detail=""):
    global failures
    if ok:
        print("ok   " + name)
    else:
        failures += 1
        print("FAIL " + name + (": " + detail if detail else ""))


schema = json.loads(subprocess.run([pfx, "schema"], check=True, capture_output=True,
                                   text=True).stdout)
defs = schema["$defs"]


def key_properties():
    """(where, key, property) of every key-table row: the top level and
    every object definition, less the `type` rows that name a kind."""
    tables = [("top", schema)] + [(n, d) for n, d in defs.items() if "properties" in d]
    for where, t in tables:
        family = "oneOf" in t and all("$ref" in b for b in t["oneOf"])
        for key, p in t["properties"].items():
            if key == "type" and ("const" in p or family):
                continue
            yield where, key, p


def forms(p):
    """The descriptions of the forms a property takes: its oneOf branches or
    those of the fragment it refers to."""
    one = p.get("oneOf")
    ref = p.get("$ref", "")
    if one is None and ref.startswith("#/$defs/"):
        one = defs[ref[len("#/$defs/"):]].get("oneOf")
    out = []
    for b in one or []:
        d = b.get("description")
        r = b.get("$ref", "")
        if d is None and r.startswith("#/$defs/"):
            d = defs[r[len("#/$defs/"):]].get("description")
        if d:
            out.append(d)
    return out


# Every row: a title (its meaning), and description and markdownDescription
# that start with it; the forms' descriptions after the meaning.
rows = list(key_properties())
bad = []
for where, key, p in rows:
    title = p.get("title")
    desc = p.get("description", "")
    md = p.get("markdownDescription", "")
    if not title or not desc.startswith(title) or not md.startswith(title):
        bad.append("%s.%s" % (where, key))
        continue
    for f in forms(p):
        if "\n- " + f not in md[len(title):]:
            bad.append("%s.%s (form %r)" % (where, key, f[:40]))
check("every key (%d) has a title, and a description and markdownDescription "
      "that start with it" % len(rows), len(rows) > 200 and not bad, ", ".join(bad[:8]))
value_keys = [(w, k) for w, k, p in rows if p.get("$ref") == "#/$defs/value"]
check("every value key (%d) lists the value's four forms after its meaning" % len(value_keys),
      len(value_keys) >= 12 and all(
          len(forms(defs[w]["properties"][k] if w != "top" else schema["properties"][k])) == 4
          for w, k in value_keys))

# Known answers: the meaning names the unit the key is written in.
units = {("emitter", "speed"): "m/s", ("emitter", "lifetime"): "Seconds",
         ("emitter", "size"): "metres", ("emitter", "gravity_scale"): "multiplier",
         ("emitter", "spin"): "degrees per second", ("force_drag", "k"): "1/s",
         ("camera", "fov"): "degrees", ("sim", "rate"): "steps per second"}
for (table, key), unit in units.items():
    p = defs[table]["properties"][key]
    check("%s.%s: its title names its unit (%s)" % (table, key, unit),
          unit in p.get("title", ""), repr(p.get("title")))

# The text is pfx lsp's hover text for the row (one source, not a copy):
# the markdownDescription up to the forms is in the hover on the key.
effect = ("pfx: 1\nduration: 1\nemitters:\n  a:\n    rate: 10\n    speed: 3\n"
          "    lifetime: [1, 2]\n    size: 0.1\n    gravity_scale: 0.5\n")
c = Client(pfx)
c.start()
uri = "file:///tmp/pfx-schema-docs.yaml"
c.notify("textDocument/didOpen", {"textDocument": {"uri": uri, "languageId": "yaml",
                                                   "version": 1, "text": effect}})
for line, key in ((5, "speed"), (6, "lifetime"), (7, "size"), (8, "gravity_scale")):
    r = c.request("textDocument/hover", {"textDocument": {"uri": uri},
                                         "position": {"line": line, "character": 5}})
    hover = ((r.get("result") or {}).get("contents") or {}).get("value", "")
    md = defs["emitter"]["properties"][key]["markdownDescription"].split("\n\nForms:")[0]
    check("emitter.%s: the schema's text is pfx lsp's hover text" % key, md in hover,
          "%r not in %r" % (md[:60], hover[:200]))
c.finish()

# Colours: every form of a colour carries the colour's error message, the
# pattern's as patternErrorMessage too, so a bad colour reads as one.
for name in ("colour", "hdr_colour"):
    branches = defs[name]["oneOf"]
    msgs = [b.get("errorMessage", "") for b in branches]
    check("$defs.%s: each of its %d forms has the colour's errorMessage" % (name, len(branches)),
          len(branches) == 3 and all(m.startswith("expected a colour: #rrggbb, #rrggbbaa, [r, g, b(, a)]")
                                     and "a CSS name such as 'orange'" in m for m in msgs), repr(msgs))
    patterned = [b for b in branches if "pattern" in b]
    check("$defs.%s: its pattern has patternErrorMessage" % name,
          len(patterned) == 1 and all(b.get("patternErrorMessage") == b["errorMessage"]
                                      for b in patterned))
sys.exit(1 if failures else 0)
