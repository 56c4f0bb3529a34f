"""A minimal LSP client over a pfx lsp subprocess, for the protocol test
and the latency benchmark: framed JSON-RPC, requests matched to their
responses by id, notifications kept in order."""
import json
import subprocess
import time


class Client:
    def __init__(self, pfx, args=("lsp",)):
        self.p = subprocess.Popen([pfx, *args], stdin=subprocess.PIPE,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        self.next_id = 1
        self.notes = []

    def send_raw(self, data):
        self.p.stdin.write(data)
        self.p.stdin.flush()

    def send(self, msg):
        body = json.dumps(msg).encode()
        self.send_raw(b"Content-Length: %d\r\n\r\n" % len(body) + body)

    def read(self):
        """The next message, or None at the end of the stream."""
        length = None
        while True:
            line = self.p.stdout.readline()
            if not line:
                return None
            line = line.strip()
            if not line:
                break
            name, _, value = line.decode().partition(":")
            if name.lower() == "content-length":
                length = int(value)
        return json.loads(self.p.stdout.read(length))

    def notify(self, method, params=None):
        self.send({"jsonrpc": "2.0", "method": method, "params": params or {}})

    def request(self, method, params=None):
        """The response to the request (notifications before it kept)."""
        rid = self.next_id
        self.next_id += 1
        self.send({"jsonrpc": "2.0", "id": rid, "method": method, "params": params or {}})
        while True:
            m = self.read()
            if m is None:
                raise EOFError("the server closed the stream waiting for %s" % method)
            if m.get("id") == rid and "method" not in m:
                return m
            self.notes.append(m)

    def wait_note(self, method, uri=None):
        """The next notification of method (for uri), in order."""
        for i, m in enumerate(self.notes):
            if m.get("method") == method and (uri is None or m["params"].get("uri") == uri):
                return self.notes.pop(i)
        while True:
            m = self.read()
            if m is None:
                raise EOFError("the server closed the stream waiting for %s" % method)
            if m.get("method") == method and (uri is None or m["params"].get("uri") == uri):
                return m
            self.notes.append(m)

    def start(self, root="/tmp"):
        r = self.request("initialize", {"processId": None, "rootUri": "file://" + root,
                                        "capabilities": {}})
        self.notify("initialized")
        return r

    def finish(self, timeout=10):
        """shutdown then exit: the exit status."""
        self.request("shutdown")
        self.notify("exit")
        self.p.stdin.close()
        return self.p.wait(timeout)
