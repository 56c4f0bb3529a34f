"""yaml-language-server (the server under VS Code's YAML extension and most
editors' YAML support) on pfx's schema, headless over stdio: every example
is clean, hover on a key shows its meaning and unit before the form its
value matched, and a bad colour reads as a colour error. Prints
`ok   NAME` / `FAIL NAME` lines for harness.sh's tally.

    python3 check_yaml_language_server.py SERVER SCHEMA SOURCE-DIR
"""
import glob
import os
import sys

server, schema, src = sys.argv[1], sys.argv[2], sys.argv[3]
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


# The schema by the document's modeline: no client configuration needed.
modeline = "# yaml-language-server: $schema=file://%s\n" % os.path.abspath(schema)
c = Client("node", (server, "--stdio"))
c.start()
version = {}


def open_doc(name, text):
    """Opens text as name; its diagnostics (the line numbers of the text,
    the modeline's left out)."""
    uri = "file:///pfx-yls/" + name
    c.notify("textDocument/didOpen", {"textDocument": {"uri": uri, "languageId": "yaml",
                                                       "version": 1, "text": modeline + text}})
    d = c.wait_note("textDocument/publishDiagnostics", uri)["params"]["diagnostics"]
    for x in d:
        x["line"] = x["range"]["start"]["line"] - 1
    return uri, d


def hover(uri, line, character):
    r = c.request("textDocument/hover", {"textDocument": {"uri": uri},
                                         "position": {"line": line + 1, "character": character}})
    return ((r.get("result") or {}).get("contents") or {}).get("value", "")


# The examples: the schema loads (a $ref it cannot resolve drops it whole)
# and accepts every one of them.
examples = sorted(glob.glob(os.path.join(src, "effects", "*.yaml")))
dirty = []
for f in examples:
    _, d = open_doc(os.path.basename(f), open(f).read())
    dirty += ["%s:%d: %s" % (os.path.basename(f), x["line"] + 1, x["message"][:80]) for x in d]
check("yaml-language-server reports nothing on the %d examples" % len(examples),
      len(examples) > 10 and not dirty, "; ".join(dirty[:5]))

effect = """pfx: 1
duration: 2
image:
  background: "#12345"
emitters:
  a:
    rate: 10
    speed: 3
    lifetime: [1, 2]
    color: "#ff00zz"
  b:
    color: 5
  c:
    color: orang
"""
uri, diags = open_doc("bad.yaml", effect)

# Hover: the meaning and unit first (the title), then the matched form.
for line, char, key, meaning, form in (
        (7, 5, "speed", "Speed at birth in m/s", "Always this number."),
        (7, 11, "speed's value", "Speed at birth in m/s", "Always this number."),
        (8, 6, "lifetime", "Seconds a particle lives", "[min, max]")):
    h = hover(uri, line, char)
    plain = h.replace("\\", "")
    check("hover on %s: '%s' first, then '%s'" % (key, meaning, form),
          plain.startswith("#### " + meaning) and form in plain and
          plain.index(meaning) < plain.index(form), repr(h[:200]))

# A bad colour: the colour's message at the colour, never a pattern.
for line, what in ((3, "#12345 (a colour)"), (9, "#ff00zz (an HDR colour)"),
                   (11, "5 (an HDR colour)"), (13, "orang (an HDR colour)")):
    msgs = [x["message"] for x in diags if x["line"] == line]
    check("a bad colour %s reads as a colour error" % what,
          msgs and all(m.startswith("expected a colour: #rrggbb, #rrggbbaa, [r, g, b(, a)]")
                       and "a CSS name such as 'orange'" in m and "pattern" not in m
                       for m in msgs), repr(msgs))
check("nothing else is reported on the bad file",
      all(x["line"] in (3, 9, 11, 13) for x in diags),
      repr([(x["line"], x["message"][:60]) for x in diags]))
c.finish()
sys.exit(1 if failures else 0)
