#!/usr/bin/python3
"""Diagnostics latency of `pfx lsp` per example: the time from a didChange
to its publishDiagnostics, the median and worst of N edits per file.

Usage: tools/lsp_latency.py [PFX] [N]   (default build/pfx, 20)

Per file: the median and worst wall time of a change sent with a request
right after it, which makes the server analyse at once (what a change
costs: load, compile, validate's estimate, the JSON; on a loaded machine
the worst is mostly waiting for a core); the server's own CPU time per
change (from /proc, immune to that wait); and one change left to the
server's 100 ms debounce, as an editor that only types does."""
import glob
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "lsp"))
from lsp_client import Client  # noqa: E402

src = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
pfx = sys.argv[1] if len(sys.argv) > 1 else os.path.join(src, "build", "pfx")
n = int(sys.argv[2]) if len(sys.argv) > 2 else 20
c = Client(pfx)
c.start(src)
print("%-22s %10s %10s %10s %12s" % ("effect", "median ms", "worst ms", "cpu ms", "debounced ms"))


def cpu_ms(pid):
    """utime + stime of process pid, in milliseconds."""
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) * 1e3 / os.sysconf("SC_CLK_TCK")


worst_cpu = 0
worst_all = 0
for path in sorted(glob.glob(os.path.join(src, "effects", "*.yaml"))):
    text = open(path).read()
    uri = "file://" + os.path.abspath(path)
    c.notify("textDocument/didOpen", {"textDocument": {"uri": uri, "languageId": "yaml",
                                                       "version": 0, "text": text}})
    c.wait_note("textDocument/publishDiagnostics", uri)
    times = []
    cpu0 = cpu_ms(c.p.pid)
    for v in range(1, n + 1):
        edited = text + "\n# edit %d\n" % v
        t0 = time.perf_counter()
        c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": v},
                                            "contentChanges": [{"text": edited}]})
        c.send({"jsonrpc": "2.0", "id": 100000 + v, "method": "textDocument/documentSymbol",
                "params": {"textDocument": {"uri": uri}}})
        got = c.wait_note("textDocument/publishDiagnostics", uri)["params"]["version"]
        times.append((time.perf_counter() - t0) * 1e3)
        assert got == v, "published version %d for change %d" % (got, v)
        while c.read().get("id") != 100000 + v:
            pass
    cpu = (cpu_ms(c.p.pid) - cpu0) / n
    worst_cpu = max(worst_cpu, cpu)
    t0 = time.perf_counter()
    c.notify("textDocument/didChange", {"textDocument": {"uri": uri, "version": n + 1},
                                        "contentChanges": [{"text": text}]})
    c.wait_note("textDocument/publishDiagnostics", uri)
    debounced = (time.perf_counter() - t0) * 1e3
    c.notify("textDocument/didClose", {"textDocument": {"uri": uri}})
    c.wait_note("textDocument/publishDiagnostics", uri)
    worst_all = max(worst_all, max(times))
    print("%-22s %10.2f %10.2f %10.2f %12.1f" % (os.path.basename(path), statistics.median(times),
                                                 max(times), cpu, debounced))
print("worst over all examples: %.2f ms wall, %.2f ms CPU per change" % (worst_all, worst_cpu))
c.finish()
