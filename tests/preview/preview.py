"""A `pfx preview` server for the tests: started on a free port, its URL
read from the first line of stdout, requests made with http.client (so
that the Host header and the path go out exactly as written), stopped
with SIGINT. Used by check_server.py and check_browser.py."""
import http.client
import json
import os
import re
import signal
import subprocess
import time

URL_LINE = re.compile(r"^http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]{32})$")


class Preview:
    def __init__(self, pfx, path, *args, cwd=None):
        # SIGINT as Control-C sends it, even where the test itself was
        # started in the background with SIGINT ignored.
        self.proc = subprocess.Popen([pfx, "preview", path, "--no-open", *args], cwd=cwd,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                     preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
        self.first_line = self.proc.stdout.readline().rstrip("\n")
        m = URL_LINE.match(self.first_line)
        if not m:
            self.proc.kill()
            raise RuntimeError("first line of stdout: %r; stderr: %r" %
                               (self.first_line, self.proc.stderr.read()))
        self.port, self.token = int(m.group(1)), m.group(2)
        self.url = self.first_line

    def get(self, path, token=True, host=None, method="GET", headers=None):
        """(status, headers, body) of one request; path is sent as is."""
        c = http.client.HTTPConnection("127.0.0.1", self.port, timeout=120)
        if token:
            path += ("&" if "?" in path else "?") + "token=" + self.token
        c.putrequest(method, path, skip_host=True)
        c.putheader("Host", host or "127.0.0.1:%d" % self.port)
        for k, v in (headers or {}).items():
            c.putheader(k, v)
        c.endheaders()
        r = c.getresponse()
        body = r.read()
        c.close()
        return r.status, dict(r.getheaders()), body

    def state(self):
        status, _, body = self.get("/api/state")
        assert status == 200, status
        return json.loads(body)

    def wait_news(self, news, timeout=20):
        """The state once its news count passes `news`."""
        end = time.time() + timeout
        while time.time() < end:
            s = self.state()
            if s["news"] > news:
                return s
            time.sleep(0.005)
        raise RuntimeError("no news after %s s" % timeout)

    def threads(self):
        return len(os.listdir("/proc/%d/task" % self.proc.pid))

    def rss_kib(self):
        with open("/proc/%d/status" % self.proc.pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
        return 0

    def stop(self, timeout=20):
        """SIGINT, then the exit status (None when it had to be killed)."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
                return None
        return self.proc.returncode

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()


def edit(path, old, new):
    """Replaces old by new in the file, written in place as many editors do."""
    with open(path) as f:
        text = f.read()
    assert old in text, old
    with open(path, "w") as f:
        f.write(text.replace(old, new, 1))


def line_of(path, text):
    """The 1-based line where text first appears in the file."""
    with open(path) as f:
        for i, line in enumerate(f, 1):
            if text in line:
                return i
    raise ValueError(text)
