"""The protocol test of `pfx lsp`: scripted sessions over stdio with the
expected response for each capability, on files with known answers.
Usage: protocol.py PFX SRC. Prints `ok   NAME` or `FAIL NAME: why` lines
(tests/harness.sh's tally counts them)."""
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lsp_client import Client  # noqa: E402

pfx, src = sys.argv[1], sys.argv[2]
failures = 0


def check(name, ok, why=""):
    global failures
    if ok:
        print("ok   " + name)
    else:
        failures += 1
        print("FAIL %s: %s" % (name, why))


def raw_session(data, timeout=10):
    """Feeds bytes to a fresh server, then closes stdin: status, stdout, stderr."""
    p = subprocess.run([pfx, "lsp"], input=data, capture_output=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


def frame(msg):
    body = json.dumps(msg).encode()
    return b"Content-Length: %d\r\n\r\n" % len(body) + body


INIT = frame({"jsonrpc": "2.0", "id": 1, "method": "initialize",
              "params": {"processId": None, "capabilities": {}}})
SHUTDOWN = frame({"jsonrpc": "2.0", "id": 2, "method": "shutdown"})
EXIT = frame({"jsonrpc": "2.0", "method": "exit"})


def messages(out):
    """The framed messages of a server's stdout."""
    msgs = []
    while out:
        head, _, rest = out.partition(b"\r\n\r\n")
        n = int(head.split(b":")[1])
        msgs.append(json.loads(rest[:n]))
        out = rest[n:]
    return msgs


def doc(uri, text, version=1):
    return {"textDocument": {"uri": uri, "languageId": "yaml", "version": version, "text": text}}


def at(text, needle, nth=0, offset=0):
    """The LSP position of the nth occurrence of needle (+ offset characters)."""
    for i, line in enumerate(text.split("\n")):
        j = line.find(needle)
        while j >= 0:
            if nth == 0:
                return {"line": i, "character": j + offset}
            nth -= 1
            j = line.find(needle, j + 1)
    raise KeyError(needle)


# ---- lifecycle and framing ------------------------------------------------

status, out, err = raw_session(INIT + SHUTDOWN + EXIT)
msgs = messages(out)
caps = msgs[0]["result"]["capabilities"] if msgs else {}
check("lifecycle: initialize announces every capability",
      all(caps.get(k) for k in ("hoverProvider", "completionProvider", "documentSymbolProvider",
                                "definitionProvider", "referencesProvider", "renameProvider",
                                "codeActionProvider", "colorProvider"))
      and caps.get("textDocumentSync", {}).get("change") == 1, json.dumps(caps))
check("lifecycle: shutdown answers null, exit after it exits 0",
      status == 0 and len(msgs) == 2 and msgs[1].get("result", 1) is None,
      "status %d, %s" % (status, msgs))

status, out, err = raw_session(INIT + EXIT)
check("lifecycle: exit without shutdown exits 1", status == 1, "status %d" % status)

status, out, err = raw_session(INIT)
check("lifecycle: the end of input without exit exits 1", status == 1, "status %d" % status)

status, out, err = raw_session(
    frame({"jsonrpc": "2.0", "id": 7, "method": "textDocument/hover", "params": {}}) + INIT +
    frame({"jsonrpc": "2.0", "id": 8, "method": "initialize", "params": {}}) +
    frame({"jsonrpc": "2.0", "id": 9, "method": "workspace/nonsense", "params": {}}) +
    b"Content-Length: 9\r\n\r\n{not json" + SHUTDOWN +
    frame({"jsonrpc": "2.0", "id": 10, "method": "textDocument/hover", "params": {}}) + EXIT)
codes = {m.get("id"): m.get("error", {}).get("code") for m in messages(out)}
check("lifecycle: errors for a request before initialize, a second initialize, an unknown "
      "method, bad JSON and a request after shutdown",
      codes == {7: -32002, 1: None, 8: -32600, 9: -32601, None: -32700, 2: None, 10: -32600}
      and status == 0, "codes %s, status %d" % (codes, status))

status, out, err = raw_session(INIT + b"Content-Length: banana\r\n\r\n{}")
check("framing: a bad Content-Length is an error (exit 1), not a crash",
      status == 1 and b"pfx: cannot read an LSP message" in err, "status %d, %r" % (status, err))

status, out, err = raw_session(b"Content-Length: 99999999999\r\n\r\n")
check("framing: a Content-Length above the bound is refused before any allocation",
      status == 1 and b"above 32 MiB" in err, "status %d, %r" % (status, err))

status, out, err = raw_session(b"X" * 20000)
check("framing: a header with no end is refused after 8 KiB",
      status == 1 and b"no end of its header" in err, "status %d, %r" % (status, err))

# A client that stops reading: a failed write, exit status 1, not SIGPIPE.
p = subprocess.Popen([pfx, "lsp"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                     stderr=subprocess.PIPE)
p.stdout.close()
try:
    p.stdin.write(INIT + INIT + SHUTDOWN + EXIT)
    p.stdin.close()
except BrokenPipeError:
    pass
status, err = p.wait(10), p.stderr.read()
check("lifecycle: a client that closed its end gets 'cannot write to the editor', status 1",
      status == 1 and b"pfx: cannot write to the editor: Broken pipe" in err,
      "status %d, %r" % (status, err))

p = subprocess.run([pfx, "lsp", "effects/fire.yaml"], capture_output=True, text=True)
check("usage: pfx lsp FILE is a usage error (exit 2): the editor sends the documents",
      p.returncode == 2 and "pfx: lsp takes no FILE" in p.stderr and not p.stdout,
      "%d %r" % (p.returncode, p.stderr))

# Split messages: a message cut in two reads still parses.
c = Client(pfx)
init = INIT
c.send_raw(init[:10])
c.send_raw(init[10:])
r = c.read()
check("framing: a message split across reads", r and r.get("id") == 1, str(r))
c.notify("initialized")
check("lifecycle: shutdown, exit: status 0 in a live session", c.finish() == 0)

# ---- diagnostics: exactly `pfx validate`'s -------------------------------


def validate(path, text=None):
    """pfx validate --format json on path: [(line, col, severity, rule, message)]."""
    p = subprocess.run([pfx, "validate", "--format", "json", path], capture_output=True,
                       text=True)
    rows = []
    for line in p.stderr.splitlines():
        o = json.loads(line)
        rows.append(o)
    return rows


def expected(rows, text):
    """validate's JSON lines as LSP diagnostics (heads and their notes)."""
    out = []
    for o in rows:
        if o["severity"] == "note":
            out[-1].setdefault("related", []).append((o["line"] - 1, o["message"]))
            continue
        out.append({"line": o["line"] - 1 if o["line"] else 0, "rule": o["rule"],
                    "severity": {"error": 1, "warning": 2}[o["severity"]],
                    "message": o["message"]})
    return out


def got(diags):
    out = []
    for g in diags:
        e = {"line": g["range"]["start"]["line"], "rule": g.get("code"),
             "severity": g["severity"], "message": g["message"]}
        # validate's notes; the server's own pointer to a suggested name's
        # definition is checked on its own below
        rel = [(r["location"]["range"]["start"]["line"], r["message"])
               for r in g.get("relatedInformation", []) if not r["message"].endswith(
                   " is defined here")]
        if rel:
            e["related"] = rel
        out.append(e)
    return out


files = sorted(glob.glob(os.path.join(src, "effects", "*.yaml")))
files += sorted(glob.glob(os.path.join(src, "tests", "diag", "*.yaml")))
c = Client(pfx)
c.start(src)
mismatch = []
for path in files:
    text = open(path, encoding="utf-8", errors="replace").read()
    uri = "file://" + path
    c.notify("textDocument/didOpen", doc(uri, text))
    d = c.wait_note("textDocument/publishDiagnostics", uri)["params"]["diagnostics"]
    c.notify("textDocument/didClose", {"textDocument": {"uri": uri}})
    c.wait_note("textDocument/publishDiagnostics", uri)
    want = expected(validate(path), text)
    if got(d) != want:
        mismatch.append("%s:\n  lsp:      %s\n  validate: %s" % (os.path.basename(path), got(d),
                                                              want))
check("diagnostics: the same as pfx validate's (rule, severity, line, message, notes) on %d "
      "files" % len(files), not mismatch, "\n".join(mismatch[:3]))

# The editor's text, not the file on disk; the range of the node; a code.
# tests/lsp/fire.yaml (pinned: the positions below are its own) in a
# folder with the two textures a completion lists, no more.
home = tempfile.mkdtemp(prefix="pfx-lsp-")
os.mkdir(os.path.join(home, "textures"))
for png in ("flame_sheet.png", "smoke_sheet.png"):
    shutil.copy(os.path.join(src, "effects", "textures", png), os.path.join(home, "textures"))
fire = os.path.join(home, "fire.yaml")
shutil.copy(os.path.join(src, "tests", "lsp", "fire.yaml"), fire)
fire_text = open(fire).read()
typo = fire_text.replace("forces: [gravity, flicker]\n    gravity_scale: -0.15",
                         "forces: [gravty, flicker]\n    gravity_scale: -0.15")
uri = "file://" + fire
c.notify("textDocument/didOpen", doc(uri, typo))
d = c.wait_note("textDocument/publishDiagnostics", uri)["params"]
g = d["diagnostics"][0] if d["diagnostics"] else {}
pos = at(typo, "gravty")
check("diagnostics: from the editor's text, at the node's range, with the rule id as code",
      len(d["diagnostics"]) == 1 and g.get("code") == "PFX4001" and g.get("severity") == 1
      and g["range"] == {"start": pos, "end": {"line": pos["line"],
                                              "character": pos["character"] + 6}}
      and "did you mean 'gravity'?" in g["message"], json.dumps(d))

rel = g.get("relatedInformation", [{}])[0]
check("diagnostics: a misspelt force points at the definition of the name suggested",
      rel.get("message") == "'gravity' is defined here"
      and rel["location"]["range"]["start"] == at(typo, "gravity: {", 0, 0), json.dumps(g))

inverted = fire_text.replace("lifetime: [0.8, 1.6]", "lifetime: [2.0, 1.2]")
c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": 2},
                                    "contentChanges": [{"text": inverted}]})
d = c.wait_note("textDocument/publishDiagnostics", uri)["params"]
g = d["diagnostics"][0] if d["diagnostics"] else {}
pos = at(inverted, "[2.0, 1.2]")
check("diagnostics: lifetime: [2.0, 1.2] (min above max) underlined whole, PFX3004",
      d["version"] == 2 and g.get("code") == "PFX3004" and g["range"]["start"] == pos
      and g["range"]["end"]["character"] == pos["character"] + 10, json.dumps(d))

# Debounce: a burst of edits is analysed once, as its newest text.
for v, t in ((3, typo), (4, inverted), (5, fire_text)):
    c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": v},
                                        "contentChanges": [{"text": t}]})
d = c.wait_note("textDocument/publishDiagnostics", uri)["params"]
c.request("textDocument/documentSymbol", {"textDocument": {"uri": uri}})
stale = [m for m in c.notes if m.get("method") == "textDocument/publishDiagnostics"]
check("diagnostics: a newer edit supersedes older ones within the debounce",
      d["version"] == 5 and d["diagnostics"] == [] and not stale, json.dumps([d, stale])[:400])

# The debounce: an edit alone is analysed 100 ms after it, not before.
import time  # noqa: E402
t0 = time.monotonic()
c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": 6},
                                    "contentChanges": [{"text": typo}]})
d = c.wait_note("textDocument/publishDiagnostics", uri)["params"]
waited = time.monotonic() - t0
check("diagnostics: an edit alone is published after the 100 ms debounce",
      d["version"] == 6 and 0.1 <= waited < 5, "%.3f s" % waited)
c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": 7},
                                    "contentChanges": [{"text": fire_text}]})
c.wait_note("textDocument/publishDiagnostics", uri)

# A note at another place becomes relatedInformation there.
dup = os.path.join(src, "tests", "diag", "duplicate_emitter.yaml")
dtext = open(dup).read()
c.notify("textDocument/didOpen", doc("file://" + dup, dtext))
d = c.wait_note("textDocument/publishDiagnostics", "file://" + dup)["params"]["diagnostics"]
rel = [g for g in d if g.get("relatedInformation")]
check("diagnostics: a note at another place is relatedInformation with its location",
      rel and rel[0]["relatedInformation"][0]["location"]["uri"] == "file://" + dup
      and rel[0]["relatedInformation"][0]["location"]["range"]["start"]["line"] !=
      rel[0]["range"]["start"]["line"], json.dumps(d))

# ---- hover -----------------------------------------------------------------


def hover(text, needle, nth=0, offset=0):
    r = c.request("textDocument/hover", {"textDocument": {"uri": uri},
                                         "position": at(text, needle, nth, offset)})
    res = r.get("result") or {}
    return res.get("contents", {}).get("value", "")


h = hover(fire_text, "speed: [0.5", offset=1)
check("hover: speed shows its meaning, unit, range and default",
      "**speed**" in h and "m/s" in h and "Default: 1" in h and "1e+06" in h, h)
h = hover(fire_text, "gravity_scale", 0, 2)
check("hover: gravity_scale shows its meaning", "multiplier of the gravity" in h, h)
h = hover(fire_text, "lifetime: 0.6", 0, 1)
check("hover: lifetime shows its unit", "Seconds a particle lives" in h, h)
h = hover(fire_text, "rate: 12", 1, 1)  # the second: sim's is rate: 120
# glow: rate 12/s, lifetime 0.6 s: floor(12 x 0.6) + 1 = 8 particles at most.
check("hover: an emitter's rate shows the pool it implies (rate 12, lifetime 0.6: 8)",
      "up to 8 live particles" in h, h)
h = hover(fire_text, "blend: add", 0, 8)
check("hover: an enum value shows its key and every choice",
      "**blend**" in h and "`add`" in h, h)
h = hover(fire_text, "type: turbulence", 0, 8)
check("hover: a force's type names the family and the kind",
      "turbulence" in h and "gravity" in h, h)
h = hover(fire_text, "gravity, flicker", 0, 2)
check("hover: a force name says what it is and counts its references",
      "(force)" in h and "2 references" in h, h)

# ---- completion --------------------------------------------------------------


def complete(text, version, pos):
    c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": version},
                                        "contentChanges": [{"text": text}]})
    r = c.request("textDocument/completion", {"textDocument": {"uri": uri}, "position": pos})
    return r.get("result") or []


half = fire_text.replace("    forces: [gravity, flicker]\n    gravity_scale: -0.15",
                         "    forces: [\n    gravity_scale: -0.15")
items = complete(half, 10, at(half, "forces: [", 0, 9))
check("completion: `forces: [` offers the file's forces (half-typed file)",
      sorted(i["label"] for i in items) == ["flicker", "gravity"], json.dumps(items)[:300])
half = fire_text.replace("    blend: add\n  glow:", "    blend: \n  glow:")
items = complete(half, 11, at(half, "blend: \n", 0, 7) if False else
                 {"line": at(half, "    blend: ")["line"], "character": 11})
labels = [i["label"] for i in items]
check("completion: `blend: ` offers the blend modes", "add" in labels and "alpha" in labels,
      str(labels))
half = fire_text.replace("    spread: 10\n", "    spread: 10\n    lif\n", 1)
items = complete(half, 12, at(half, "    lif", 0, 7))
charge = [i for i in items if i["label"] == "charge"]
labels = [i["label"] for i in items]
check("completion: an emitter's keys not yet written, each with its meaning",
      charge and "charge in coulombs" in charge[0]["documentation"]["value"]
      and "lifetime" not in labels and "gravity_scale" not in labels and "mass" in labels,
      json.dumps(items)[:300])
half = fire_text.replace("flicker: { type: turbulence,", "flicker: { type: turbulence, s")
items = complete(half, 18, at(half, "turbulence, s", 0, 13))
labels = [i["label"] for i in items]
check("completion: in a flow mapping, the keys of the type it names",
      "strength" in labels and "octaves" in labels and "accel" not in labels, str(labels))
half = fire_text.replace("type: turbulence", "type: ")
items = complete(half, 13, at(half, "flicker: { type: ", 0, 17))
labels = [i["label"] for i in items]
check("completion: a force's `type: ` offers the force kinds",
      "turbulence" in labels and "vortex" in labels and "sphere" not in labels, str(labels))
half = fire_text.replace("    blend: add\n  glow:",
                         "    blend: add\n    on_death: [{ emit: }]\n  glow:")
items = complete(half, 14, at(half, "emit: }", 0, 6))
check("completion: `emit:` offers the file's emitters",
      sorted(i["label"] for i in items) == ["flame", "glow", "sparks"], json.dumps(items)[:300])
items = complete(fire_text, 15, at(fire_text, "forces:", 0, 0))
labels = [i["label"] for i in items]
check("completion: the top level's keys at column 0, but those written elsewhere",
      "forces" in labels and "light" in labels and "emitters" not in labels, str(labels))

half = fire_text.replace("texture: textures/flame_sheet.png", "texture: textures/fl")
pos = at(half, "textures/fl", 0, 11)
items = complete(half, 16, pos)
check("completion: texture offers the PNG files beside the effect, replacing what is typed",
      [i["label"] for i in items] == ["textures/flame_sheet.png", "textures/smoke_sheet.png"]
      and items[0]["textEdit"]["range"]["start"]["character"] == pos["character"] - 11,
      json.dumps(items)[:300])
half = fire_text.replace("texture: textures/flame_sheet.png", 'texture: "')
items = complete(half, 17, at(half, 'texture: "', 0, 10))
check("completion: a quoted texture path starts with the folders beside the effect",
      [i["label"] for i in items] == ["textures/"], json.dumps(items)[:300])

# ---- outline, definition, references, rename -------------------------------
c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": 20},
                                    "contentChanges": [{"text": fire_text}]})
syms = c.request("textDocument/documentSymbol", {"textDocument": {"uri": uri}})["result"]
names = {s["name"]: [k["name"] for k in s.get("children", [])] for s in syms}
check("documentSymbol: the outline of camera, image, forces and emitters",
      names.get("emitters") == ["flame", "glow", "sparks"]
      and names.get("forces") == ["gravity", "flicker"] and "camera" in names
      and "image" in names, json.dumps(names))
forces = [s for s in syms if s["name"] == "forces"]
check("documentSymbol: a force's detail is its type",
      forces and [k.get("detail") for k in forces[0]["children"]] == ["gravity", "turbulence"],
      json.dumps(forces)[:300])

r = c.request("textDocument/definition", {"textDocument": {"uri": uri},
                                          "position": at(fire_text, "gravity, flicker", 1, 3)})
res = r.get("result") or {}
check("definition: a force in an emitter's list goes to its key under forces",
      res.get("range", {}).get("start") == at(fire_text, "  gravity: {", 0, 2), json.dumps(r))
r = c.request("textDocument/references", {"textDocument": {"uri": uri},
                                          "position": at(fire_text, "flicker:", 0, 1),
                                          "context": {"includeDeclaration": True}})
lines = sorted(x["range"]["start"]["line"] for x in r.get("result") or [])
check("references: flicker is defined once and listed by two emitters",
      lines == [at(fire_text, "flicker:")["line"], at(fire_text, "gravity, flicker")["line"],
                at(fire_text, "gravity, flicker", 1)["line"]], str(lines))
r = c.request("textDocument/rename", {"textDocument": {"uri": uri},
                                      "position": at(fire_text, "gravity: {", 0, 1),
                                      "newName": "g"})
edits = (r.get("result") or {}).get("changes", {}).get(uri, [])
check("rename: gravity to g edits its key and both references (not gravity_scale)",
      len(edits) == 3 and all(e["newText"] == "g" and
                              e["range"]["end"]["character"] - e["range"]["start"]["character"]
                              == 7 for e in edits), json.dumps(edits))
r = c.request("textDocument/rename", {"textDocument": {"uri": uri},
                                      "position": at(fire_text, "gravity: {", 0, 1),
                                      "newName": "no spaces"})
check("rename: a name that is not a plain key is refused",
      r.get("error", {}).get("code") == -32602, str(r))
r = c.request("textDocument/rename", {"textDocument": {"uri": uri},
                                      "position": at(fire_text, "gravity: {", 0, 1),
                                      "newName": "flicker"})
check("rename: a force cannot take another force's name",
      r.get("error", {}).get("code") == -32602, str(r))

# ---- code actions ----------------------------------------------------------
c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": 30},
                                    "contentChanges": [{"text": typo}]})
d = {}
while d.get("version") != 30:  # past the publications of the completion edits
    d = c.wait_note("textDocument/publishDiagnostics", uri)["params"]
d = d["diagnostics"]
r = c.request("textDocument/codeAction", {"textDocument": {"uri": uri},
                                          "range": d[0]["range"],
                                          "context": {"diagnostics": d}})
acts = r.get("result") or []
fix = acts[0]["edit"]["changes"][uri][0] if acts else {}
check("codeAction: did you mean 'gravity' becomes an edit of the typo",
      acts and acts[0]["title"] == "Change to 'gravity'" and fix.get("newText") == "gravity"
      and fix.get("range") == d[0]["range"], json.dumps(acts)[:400])
warn = {"range": {"start": {"line": 5, "character": 0}, "end": {"line": 5, "character": 3}},
        "severity": 2, "code": "PFX5004", "source": "pfx", "message": "a warning"}
r = c.request("textDocument/codeAction", {"textDocument": {"uri": uri}, "range": warn["range"],
                                          "context": {"diagnostics": [warn]}})
acts = r.get("result") or []
ed = acts[0]["edit"]["changes"][uri][0] if acts else {}
pfx_line = at(typo, "pfx: 1")["line"]
check("codeAction: a warning can be allowed with an `allow:` block after `pfx:`",
      acts and acts[0]["title"] == "Allow PFX5004 in this file"
      and ed.get("newText") == 'allow:\n  PFX5004: "why this is intended"\n'
      and ed["range"]["start"] == {"line": pfx_line + 1, "character": 0}, json.dumps(acts))

# A stability warning's fix: the integrator it names, in that emitter.
unstable = ("pfx: 1\nforces:\n  air: { type: drag, k: 500 }\nemitters:\n  puff:\n"
            "    rate: 10\n    integrator: symplectic\n    forces: [air]\n")
uuri = "file:///tmp/unstable.yaml"
c.notify("textDocument/didOpen", doc(uuri, unstable))
d = c.wait_note("textDocument/publishDiagnostics", uuri)["params"]["diagnostics"]
r = c.request("textDocument/codeAction", {"textDocument": {"uri": uuri}, "range": d[0]["range"],
                                          "context": {"diagnostics": d}})
acts = [a for a in r.get("result") or [] if a["title"].startswith("Use integrator")]
ed = acts[0]["edit"]["changes"][uuri][0] if acts else {}
check("codeAction: an unstable integrator is replaced by the one the warning names",
      d and d[0]["code"] == "PFX5001" and acts
      and acts[0]["title"] == "Use integrator 'exact' in emitter 'puff'"
      and ed["newText"] == "exact" and ed["range"]["start"] == at(unstable, "symplectic"),
      json.dumps([d, r])[:600])
fixed = unstable.replace("symplectic", "exact")
c.notify("textDocument/didChange", {"textDocument": {"uri": uuri, "version": 2},
                                    "contentChanges": [{"text": fixed}]})
d = c.wait_note("textDocument/publishDiagnostics", uuri)["params"]["diagnostics"]
check("codeAction: with the fix applied the warning is gone", d == [], json.dumps(d))

# Hover on a drag's k: k*dt = 300 / 120 = 2.5; the decay is stable below
# k*dt = 2 for Euler, symplectic, midpoint and Verlet (|1 - z| < 1 and
# |1 - z + z^2/2| < 1), below 2.785 for RK4, and always for the exact flow
# (and Boris' split step, which uses it).
drag = unstable.replace("k: 500", "k: 300")
c.notify("textDocument/didChange", {"textDocument": {"uri": uuri, "version": 3},
                                    "contentChanges": [{"text": drag}]})
r = c.request("textDocument/hover", {"textDocument": {"uri": uuri},
                                     "position": at(drag, "k: 300")})
h = (r.get("result") or {}).get("contents", {}).get("value", "")
check("hover: a drag's k shows k*dt at the sim rate and the stable integrators",
      "k*dt = 2.5 at sim.rate 120" in h
      and "Stable: `rk4`, `exact`, `boris`. Unstable: `euler`, `symplectic`, `midpoint`, "
          "`verlet`." in h, h)

# ---- colours ---------------------------------------------------------------
c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": 40},
                                    "contentChanges": [{"text": fire_text}]})
cols = c.request("textDocument/documentColor", {"textDocument": {"uri": uri}})["result"]
first = cols[1] if len(cols) > 1 else {}
want = {"red": 1.0, "green": 0xd8 / 255, "blue": 0x90 / 255, "alpha": 0xb0 / 255}
check("documentColor: background: transparent, then every gradient stop of fire.yaml "
      "(5 + 3 + 3), #ffd890b0 first",
      len(cols) == 12 and cols[0]["color"] == {"red": 0, "green": 0, "blue": 0, "alpha": 0}
      and cols[0]["range"]["start"] == at(fire_text, "transparent")
      and all(abs(first["color"][k] - v) < 1e-6 for k, v in want.items())
      and first["range"]["start"] == at(fire_text, '"#ffd890b0"'), json.dumps(cols[:2]))
r = c.request("textDocument/colorPresentation", {
    "textDocument": {"uri": uri}, "range": first.get("range"),
    "color": {"red": 1, "green": 0, "blue": 0, "alpha": 0.5}})
res = r.get("result") or [{}]
check("colorPresentation: a picked colour written back as a quoted hex",
      res[0].get("label") == '"#ff000080"' and res[0]["textEdit"]["newText"] == '"#ff000080"',
      json.dumps(r))
lst = "pfx: 1\nimage:\n  background: [0.5, 0.25, 1]\n"
c.notify("textDocument/didOpen", doc("file:///tmp/lst.yaml", lst))
cols = c.request("textDocument/documentColor",
                 {"textDocument": {"uri": "file:///tmp/lst.yaml"}})["result"]
check("documentColor: [r, g, b] under a colour key",
      len(cols) == 1 and cols[0]["color"] == {"red": 0.5, "green": 0.25, "blue": 1, "alpha": 1},
      json.dumps(cols))
# CSS colour names and transparent, read as the compiler reads them, under
# colour keys alone (an emitter named red has none); a quoted hex beside
# them once. rebeccapurple is #663399: 0x66 / 255 = 0.4, 0x33 / 255 = 0.2.
named = ('pfx: 1\nimage:\n  background: rebeccapurple\nemitters:\n  red:\n'
         '    color: {random: [red, transparent]}\n  b:\n    color: [orange, "#0000ff"]\n')
c.notify("textDocument/didOpen", doc("file:///tmp/named.yaml", named))
cols = c.request("textDocument/documentColor",
                 {"textDocument": {"uri": "file:///tmp/named.yaml"}})["result"]
want = [("rebeccapurple", (0.4, 0.2, 0.6, 1)), ("red, trans", (1, 0, 0, 1)),
        ("transparent", (0, 0, 0, 0)), ("orange", (1, 0xa5 / 255, 0, 1)),
        ('"#0000ff"', (0, 0, 1, 1))]
check("documentColor: CSS names and transparent under colour keys, {random} and lists included",
      len(cols) == len(want) and all(
          col["range"]["start"] == at(named, text) and
          all(abs(col["color"][k] - v) < 1e-6
              for k, v in zip(("red", "green", "blue", "alpha"), rgba))
          for col, (text, rgba) in zip(cols, want)), json.dumps(cols))
# A huge document: the load's own limit, and the server goes on.
huge = "pfx: 1\n" + "#" * (17 << 20) + "\n"
c.notify("textDocument/didOpen", doc("file:///tmp/huge.yaml", huge))
d = c.wait_note("textDocument/publishDiagnostics", "file:///tmp/huge.yaml")["params"]
r = c.request("textDocument/hover", {"textDocument": {"uri": uri},
                                     "position": at(fire_text, "speed:", 0, 1)})
check("robust: a 17 MiB document is reported too large (PFX6002) and the server answers on",
      [g.get("code") for g in d["diagnostics"]] == ["PFX6002"] and "m/s" in json.dumps(r),
      json.dumps(d)[:300])
status = c.finish()
check("lifecycle: a long session ends with status 0", status == 0, "status %d" % status)
shutil.rmtree(home, ignore_errors=True)
sys.exit(1 if failures else 0)
