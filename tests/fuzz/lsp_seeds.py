#!/usr/bin/python3
"""Writes the seed corpus of fuzz_lsp.c into DIR: for each effect of
effects/ (and a few diagnostics cases), one whole session as JSON bodies
separated by 0x1e bytes: initialize, the file opened, a request of every
capability at several places, an edit, shutdown and exit; plus a raw
framed stream. Usage: lsp_seeds.py SRC DIR."""
import glob
import json
import os
import sys

src, out = sys.argv[1], sys.argv[2]
uri = "file:///nonexistent/fuzz.yaml"


def session(text):
    lines = text.split("\n")
    msgs = [{"jsonrpc": "2.0", "id": 1, "method": "initialize", "params": {"capabilities": {}}},
            {"jsonrpc": "2.0", "method": "initialized", "params": {}},
            {"jsonrpc": "2.0", "method": "textDocument/didOpen",
             "params": {"textDocument": {"uri": uri, "languageId": "yaml", "version": 1,
                                         "text": text}}}]
    doc = {"uri": uri}
    n = 2
    for i in range(0, len(lines), max(1, len(lines) // 6)):
        ch = min(len(lines[i]), 6)
        pos = {"line": i, "character": ch}
        for method in ("hover", "completion", "definition", "references", "rename"):
            params = {"textDocument": doc, "position": pos}
            if method == "rename":
                params["newName"] = "renamed"
            if method == "references":
                params["context"] = {"includeDeclaration": True}
            msgs.append({"jsonrpc": "2.0", "id": n, "method": "textDocument/" + method,
                         "params": params})
            n += 1
    rng = {"start": {"line": 3, "character": 2}, "end": {"line": 3, "character": 9}}
    msgs += [
        {"jsonrpc": "2.0", "id": n, "method": "textDocument/documentSymbol",
         "params": {"textDocument": doc}},
        {"jsonrpc": "2.0", "id": n + 1, "method": "textDocument/documentColor",
         "params": {"textDocument": doc}},
        {"jsonrpc": "2.0", "id": n + 2, "method": "textDocument/colorPresentation",
         "params": {"textDocument": doc, "range": rng,
                    "color": {"red": 1, "green": 0.5, "blue": 0, "alpha": 1}}},
        {"jsonrpc": "2.0", "id": n + 3, "method": "textDocument/codeAction",
         "params": {"textDocument": doc, "range": rng, "context": {"diagnostics": [
             {"range": rng, "severity": 2, "code": "PFX5004", "message": "x"},
             {"range": rng, "severity": 1, "code": "PFX2001",
              "message": "unknown key 'x'; did you mean 'rate'?"}]}}},
        {"jsonrpc": "2.0", "method": "textDocument/didChange",
         "params": {"textDocument": {"uri": uri, "version": 2},
                    "contentChanges": [{"range": rng, "text": "rat"}, {"text": text[:200]}]}},
        {"jsonrpc": "2.0", "method": "textDocument/didClose", "params": {"textDocument": doc}},
        {"jsonrpc": "2.0", "id": n + 4, "method": "shutdown"},
        {"jsonrpc": "2.0", "method": "exit"}]
    return b"\x1e".join(json.dumps(m).encode() for m in msgs)


os.makedirs(out, exist_ok=True)
files = sorted(glob.glob(os.path.join(src, "effects", "*.yaml")))
files += sorted(glob.glob(os.path.join(src, "tests", "diag", "*.yaml")))[:20]
for path in files:
    with open(path, "rb") as f:
        text = f.read().decode("utf-8", "replace")
    with open(os.path.join(out, "lsp-" + os.path.basename(path)), "wb") as f:
        f.write(session(text))
body = json.dumps({"jsonrpc": "2.0", "id": 1, "method": "initialize", "params": {}}).encode()
with open(os.path.join(out, "lsp-raw"), "wb") as f:
    f.write(b"Content-Length: %d\r\n\r\n%s" % (len(body), body) + b"Content-Length: 5\r\n\r\n[1,2]")
