"""The contract of `pfx preview` (man pfx(1), PREVIEW) through its HTTP
routes, no browser: the URL line, loopback, the token and Host checks,
paths outside the table, frames equal to `pfx render`, live reload of a
good and a broken save, pick, a port in use, 200 edits, Control-C.
Usage: check_server.py PFX SRC WORK; prints one `ok`/`FAIL` line a check."""
import base64
import http.client
import io
import json
import os
import re
import shutil
import subprocess
import sys
import time

from PIL import Image

sys.path.insert(0, os.path.dirname(__file__))
from preview import Preview, edit, line_of  # noqa: E402

pfx, src, work = sys.argv[1:4]
failures = 0


def check(name, ok, detail=""):
    global failures
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + detail))
    failures += not ok


def pixel(png, x, y):
    return Image.open(io.BytesIO(png)).convert("RGBA").getpixel((x, y))


def near(p, want, tol=3):
    return all(abs(a - b) <= tol for a, b in zip(p, want))


dot = os.path.join(work, "dot.yaml")
shutil.copy(os.path.join(src, "tests/preview/dot.yaml"), dot)
K = 5

with Preview(pfx, "dot.yaml", cwd=work) as p:
    check("the first line of stdout is http://127.0.0.1:PORT/?token=TOKEN", True)
    # Listening on loopback alone: the socket's local address in /proc/net/tcp.
    with open("/proc/net/tcp") as f:
        rows = [line.split() for line in f.readlines()[1:]]
    mine = [r for r in rows if r[3] == "0A" and int(r[1].split(":")[1], 16) == p.port]
    check("it listens on 127.0.0.1 only", len(mine) == 1 and mine[0][1].startswith("0100007F:"),
          str(mine))

    # Security: token, Host, paths.
    st, _, _ = p.get("/api/state", token=False)
    check("no token: 403", st == 403, str(st))
    st, _, _ = p.get("/api/state?token=" + "0" * 32, token=False)
    check("a wrong token: 403", st == 403, str(st))
    st, _, _ = p.get("/frame/0.png", token=False)
    check("a frame without the token: 403", st == 403, str(st))
    st, _, _ = p.get("/api/state", host="evil.example:%d" % p.port)
    check("a foreign Host: 403", st == 403, str(st))
    st, _, _ = p.get("/api/state", host="127.0.0.1")
    check("a Host without the port: 403", st == 403, str(st))
    for host in ("localhost:%d" % p.port, "[::1]:%d" % p.port):
        st, _, _ = p.get("/api/state", host=host)
        check("Host %s: 200" % host.rsplit(":", 1)[0], st == 200, str(st))
    for path in ("/../api/state", "/frame/../../etc/passwd", "/etc/passwd", "/frame/x.png",
                 "/frame/1.png/..", "/app.js/../index.html", "/api/state/"):
        st, _, _ = p.get(path)
        check("%s: 404" % path, st == 404, str(st))
    st, _, _ = p.get("/", method="POST")
    check("POST /: 404", st == 404, str(st))
    # A request past the header bound is refused, and the server lives on.
    try:
        st, _, _ = p.get("/api/state", headers={"X-Big": "x" * 65536})
    except (ConnectionError, http.client.HTTPException):
        st = "closed"
    st2, _, _ = p.get("/api/state")
    check("a 64 KiB header: refused (4xx or closed), the server still answers",
          (st == "closed" or 400 <= st < 500) and st2 == 200, "%s %s" % (st, st2))
    # A body is refused from its headers, before it is read.
    c = http.client.HTTPConnection("127.0.0.1", p.port, timeout=30)
    try:
        c.putrequest("POST", "/api/state?token=" + p.token, skip_host=True)
        c.putheader("Host", "127.0.0.1:%d" % p.port)
        c.putheader("Content-Length", "100000")
        c.endheaders()
        c.send(b"x" * 100000)
        st = c.getresponse().status
    except (ConnectionError, http.client.HTTPException) as e:
        st = type(e).__name__
    c.close()
    check("a request with a 100 kB body: 413, the server still answers",
          st == 413 and p.get("/api/state")[0] == 200, str(st))
    st, _, _ = p.get("/api/state", token=False,
                     headers={"Cookie": "pfx_token_%d=%s" % (p.port, p.token)})
    check("the token in the page's cookie: 200", st == 200, str(st))
    st, hdr, body = p.get("/")
    check("GET / serves the page and sets the token's cookie",
          st == 200 and b"app.js" in body and hdr.get("Set-Cookie", "").startswith(
              "pfx_token_%d=%s;" % (p.port, p.token)) and "HttpOnly" in hdr["Set-Cookie"],
          "%d %s" % (st, hdr.get("Set-Cookie")))
    st, hdr, body = p.get("/app.js")
    check("GET /app.js: the page's script, no CDN",
          st == 200 and hdr["Content-Type"].startswith("text/javascript") and b"EventSource" in body
          and b"http" not in body.replace(b"http.client", b""), str(st))

    # The state.
    s = p.state()
    lines = {"dot": line_of(dot, "  dot:"), "side": line_of(dot, "  side:")}
    check("/api/state: file, version, frames, fps, size, emitters with lines",
          s["file"] == "dot.yaml" and s["version"] == 1 and s["frames"] == 10 and s["fps"] == 10
          and s["size"] == [96, 96] and s["diagnostics"] == []
          and [(e["name"], e["line"]) for e in s["emitters"]] == [("dot", lines["dot"]),
                                                                  ("side", lines["side"])],
          json.dumps(s)[:300])

    # Frame K against pfx render --frames K, byte for byte and by pixels.
    st, hdr, png = p.get("/frame/%d.png" % K)
    subprocess.run([pfx, "render", "dot.yaml", "--frames", str(K), "-o", "r", "-q"], cwd=work,
                   check=True)
    with open(os.path.join(work, "r/dot_%04d.png" % K), "rb") as f:
        rendered = f.read()
    check("/frame/K.png is the file pfx render --frames K writes", st == 200 and png == rendered,
          "status %d, %d vs %d bytes" % (st, len(png), len(rendered)))
    check("frame K: red in the middle, green to the right, black in the corner",
          near(pixel(png, 48, 48), (255, 0, 0, 255)) and near(pixel(png, 79, 48), (0, 255, 0, 255))
          and near(pixel(png, 2, 2), (0, 0, 0, 255)),
          "%s %s %s" % (pixel(png, 48, 48), pixel(png, 79, 48), pixel(png, 2, 2)))
    st, _, _ = p.get("/frame/10.png")
    check("a frame past the end: 404", st == 404, str(st))

    # Pick: the emitter and the line of its key.
    def pick(x, y):
        st, _, body = p.get("/pick?frame=%d&x=%d&y=%d" % (K, x, y))
        return json.loads(body) if st == 200 else st
    check("pick in the middle: dot and its line",
          pick(48, 48) == [{"emitter": "dot", "line": lines["dot"]}], str(pick(48, 48)))
    check("pick on the right disc: side and its line",
          pick(79, 48) == [{"emitter": "side", "line": lines["side"]}], str(pick(79, 48)))
    check("pick in the corner: nothing", pick(2, 2) == [], str(pick(2, 2)))
    # The dot's footprint: 1.2 m across at 5 m under a 40 degree field of
    # view over 96 pixels is 1.2 x 48 / (5 tan 20 deg) = 31.65 px, a radius
    # of 15.8 px around the centre (48, 48): pixel 63 (centre 63.5) is in,
    # pixel 65 (65.5) is out, and the side disc starts at 79.6 - 10.5 = 69.1.
    check("pick at the dot's edge: pixel 63 in, pixel 65 out",
          pick(63, 47) == [{"emitter": "dot", "line": lines["dot"]}] and pick(65, 47) == [],
          "%s %s" % (pick(63, 47), pick(65, 47)))
    check("pick outside the frame: 400", pick(96, 0) == 400, str(pick(96, 0)))

    # A good save: a new version, the new colour.
    news = s["news"]
    edit(dot, '"#ff0000"', '"#0000ff"')
    s = p.wait_news(news)
    st, hdr, png = p.get("/frame/%d.png" % K)
    check("an edit of a colour: version 2 and a blue middle",
          s["version"] == 2 and hdr.get("X-Pfx-Version") == "2"
          and near(pixel(png, 48, 48), (0, 0, 255, 255)), "%s %s" % (s["version"], pixel(png, 48, 48)))

    # A broken save: its diagnostics, exactly as validate prints them; the
    # last good frames stay.
    news = s["news"]
    edit(dot, "size: 1.2", "size: 1.2.")
    s = p.wait_news(news)
    v = subprocess.run([pfx, "validate", "dot.yaml"], cwd=work, capture_output=True, text=True)
    m = re.match(r"dot\.yaml:(\d+):(\d+): error:", v.stderr)
    d = s["diagnostics"]
    check("a typo: its diagnostic at line:col, as validate prints it",
          m and len(d) >= 1 and d[0]["line"] == int(m.group(1)) == line_of(dot, "size: 1.2.")
          and d[0]["column"] == int(m.group(2)) and d[0]["severity"] == "error" and d[0]["rule"]
          and s["diagnostics_text"] == v.stderr,
          "%r vs %r" % (s["diagnostics_text"], v.stderr))
    st, hdr, png = p.get("/frame/%d.png" % K)
    check("a typo: the last good frames are still served",
          s["version"] == 2 and st == 200 and hdr.get("X-Pfx-Version") == "2"
          and near(pixel(png, 48, 48), (0, 0, 255, 255)), str(st))
    news = s["news"]
    edit(dot, "size: 1.2.", "size: 1.2")
    s = p.wait_news(news)
    check("the fix clears the diagnostics and raises the version",
          s["diagnostics"] == [] and s["diagnostics_text"] == "" and s["version"] == 3, json.dumps(s)[:200])

    # 200 edits in a row: memory and threads bounded.
    p.get("/frame/0.png")
    time.sleep(0.5)
    threads0 = p.threads()
    rss = []
    colours = ['"#0000ff"', '"#00ffff"']
    for i in range(200):
        news = p.state()["news"]
        edit(dot, colours[i % 2], colours[(i + 1) % 2])
        p.wait_news(news)
        if i % 20 == 0:
            p.get("/frame/%d.png" % (i % 10))
        if i in (20, 199):
            rss.append(p.rss_kib())
    st, hdr, png = p.get("/frame/%d.png" % K)
    time.sleep(1.0)
    threads1 = p.threads()
    check("200 edits: every one compiled, the last one shown",
          p.state()["version"] == 203 and near(pixel(png, 48, 48), (0, 0, 255, 255)),
          "version %d" % p.state()["version"])
    check("200 edits: RSS grew by under 16 MiB after the first 20",
          rss[1] - rss[0] < 16 * 1024, "%d KiB -> %d KiB" % tuple(rss))
    check("200 edits: no thread left behind", threads1 <= threads0,
          "%d threads before, %d after" % (threads0, threads1))
    print("# 200 edits: RSS %d KiB after 20, %d KiB after 200; threads %d -> %d"
          % (rss[0], rss[1], threads0, threads1))

    # The port in use: a one-line error, exit 1.
    r = subprocess.run([pfx, "preview", "dot.yaml", "--no-open", "--port", str(p.port)],
                       cwd=work, capture_output=True, text=True, timeout=30)
    check("--port in use: one line, exit 1",
          r.returncode == 1 and r.stdout == "" and r.stderr.count("\n") == 1
          and "cannot listen on 127.0.0.1:%d: Address already in use" % p.port in r.stderr,
          "%d %r" % (r.returncode, r.stderr))

    # Control-C: a clean exit, nothing left in the scratch directory.
    status = p.stop()
    check("SIGINT: a clean stop, exit 0", status == 0, "status %s" % status)

# A file that does not compile yet: served with its diagnostics, no
# frames, until a good save.
edit(dot, "speed: 0", "speed: [")
with Preview(pfx, "dot.yaml", cwd=work) as p:
    s = p.state()
    st, _, _ = p.get("/frame/0.png")
    check("a broken file at start: version 0, its diagnostics, no frames (404)",
          s["version"] == 0 and s["diagnostics"] and s["frames"] == 0 and st == 404,
          "%s %s" % (json.dumps(s)[:200], st))
    edit(dot, "speed: [", "speed: 0")
    s = p.wait_news(s["news"])
    st, _, png = p.get("/frame/%d.png" % K)
    check("then a good save: version 1 and its frames",
          s["version"] == 1 and st == 200 and near(pixel(png, 48, 48), (0, 0, 255, 255)),
          "%s %s" % (s["version"], st))
    p.stop()

# --max-memory: a version whose render is estimated over the bound is
# refused as pfx render refuses it, with the same message.
with Preview(pfx, "dot.yaml", "--max-memory", "1K", cwd=work) as p:
    s = p.state()
    r = subprocess.run([pfx, "render", "dot.yaml", "-o", "big", "--max-memory", "1K"], cwd=work,
                       capture_output=True, text=True)
    msg = r.stderr.split("pfx: ", 1)[-1].split(" [PFX")[0].strip()
    check("--max-memory: a version over the bound is refused as render refuses it",
          s["version"] == 0 and r.returncode == 1 and len(s["diagnostics"]) == 1
          and s["diagnostics"][0]["message"] == msg and "--max-memory" in msg,
          "%s / %r" % (s["diagnostics"], r.stderr))
    p.stop()

# A save cancels the stale render at once, mid-frame (between simulation
# steps and motion-blur samples), and renders the playhead's frame first:
# frame 9 of slow.yaml costs a long run-up and 32 blur samples; a save 20%
# into it gets the new (cheap) version's frame 9 in well under what the
# rest of the stale frame would cost. Timed against that frame's own cost
# measured here, so a loaded machine stretches both.
slow = os.path.join(work, "slow.yaml")
with open(slow, "w") as f:
    f.write("""pfx: 1
duration: 1
fps: 10
seed: 1
sim: { rate: 10000 }
camera: { position: [0, 0, 5], target: [0, 0, 0], fov: 40 }
image: { size: [96, 96], background: "#000000", motion_blur: { shutter: 0.5, samples: 32 } }
emitters:
  dot:
    rate: 50000
    speed: 1
    lifetime: 1
    size: 0.05
    sprite: round
    color: "#ff0000"
    blend: add
""")
with Preview(pfx, "slow.yaml", cwd=work) as p:
    t0 = time.time()
    st1, _, _ = p.get("/frame/9.png")
    full = time.time() - t0
    p.stop()
with Preview(pfx, "slow.yaml", cwd=work) as p:
    import threading
    stale = threading.Thread(target=lambda: p.get("/frame/9.png"))
    stale.start()
    time.sleep(0.2 * full)
    news = p.state()["news"]
    saved = time.time()
    edit(slow, "    rate: 50000", "    rate: 50")
    s = p.wait_news(news)
    st2, h2, _ = p.get("/frame/9.png")
    latency = time.time() - saved
    stale.join()
    check("a save mid-frame cancels the stale render: the new frame 9 in under a quarter of the old "
          "frame's cost",
          st1 == st2 == 200 and s["version"] == 2 and h2.get("X-Pfx-Version") == "2" and
          latency < 0.25 * full,
          "%s %s v%s: %.0f ms after the save, the stale frame costs %.0f ms" %
          (st1, st2, h2.get("X-Pfx-Version"), latency * 1e3, full * 1e3))
    print("# save -> new frame 9: %.0f ms; the stale frame alone: %.0f ms" % (latency * 1e3, full * 1e3))
    p.stop()

# The frame cache's cap (man pfx(1)): every frame's PNG at most, (4w + 1)h
# + that / 64 + 1024 bytes a frame, but at most half of what --max-memory
# leaves beside the render's estimate (pfx info's); a tiny one evicts and
# every frame is still served, byte for byte as pfx render writes it.
shutil.copy(os.path.join(src, "tests/preview/dot.yaml"), os.path.join(work, "cap.yaml"))
info = json.loads(subprocess.run([pfx, "info", "cap.yaml", "--format", "json"], cwd=work,
                                 capture_output=True, text=True, check=True).stdout)
rows = (4 * 96 + 1) * 96
with Preview(pfx, "cap.yaml", cwd=work) as p:
    s = p.state()
    cache = s.get("cache") or {}
    check("the frame cache's cap: all frames' PNG bytes at most (--max-memory's default is larger)",
          cache.get("cap") == 10 * (rows + rows // 64 + 1024) and cache.get("bytes", -1) >= 0,
          str(cache))
    p.stop()
bound = int(info["memory"]["total_bytes"]) + 1 + 2 * 1500
with Preview(pfx, "cap.yaml", "--max-memory", str(bound), cwd=work) as p:
    served = []
    for k in range(10):
        st, _, png = p.get("/frame/%d.png" % k)
        r = subprocess.run([pfx, "render", "cap.yaml", "--frames", str(k), "-o", "cap%d" % k,
                            "--max-memory", str(bound)], cwd=work, capture_output=True)
        with open(os.path.join(work, "cap%d" % k, "cap_%04d.png" % k), "rb") as f:
            served.append(st == 200 and png == f.read() and near(pixel(png, 48, 48), (255, 0, 0, 255)))
    cache = p.state().get("cache") or {}
    check("a tiny --max-memory: cap = (bound - the render's estimate) / 2, frames evicted, "
          "every frame still served as pfx render writes it",
          all(served) and cache.get("cap") == (bound - info["memory"]["total_bytes"]) // 2 and
          cache.get("bytes", 1e9) <= max(cache["cap"], 3000) and cache.get("frames", 10) < 10,
          "%s %s" % (served, cache))
    p.stop()

# What the file reads is watched too: a texture rewritten in place, then
# replaced by a rename (as editors and exporters save).
tex = os.path.join(work, "tex.yaml")
with open(os.path.join(src, "tests/preview/dot.yaml")) as f:
    text = f.read()
with open(tex, "w") as f:
    f.write(text.replace('    color: "#ff0000"\n', '    color: "#ff0000"\n    texture: t.png\n'))
Image.new("RGBA", (8, 8), (255, 255, 255, 255)).save(os.path.join(work, "t.png"))
with Preview(pfx, "tex.yaml", cwd=work) as p:
    st, _, png = p.get("/frame/%d.png" % K)
    first = pixel(png, 48, 48)
    s = p.state()
    Image.new("RGBA", (8, 8), (0, 255, 0, 255)).save(os.path.join(work, "t.png"))
    s = p.wait_news(s["news"])
    st, _, png = p.get("/frame/%d.png" % K)
    second = pixel(png, 48, 48)
    Image.new("RGBA", (8, 8), (255, 255, 255, 255)).save(os.path.join(work, "t.tmp.png"))
    os.replace(os.path.join(work, "t.tmp.png"), os.path.join(work, "t.png"))
    s = p.wait_news(s["news"])
    st, _, png = p.get("/frame/%d.png" % K)
    third = pixel(png, 48, 48)
    check("a texture saved in place, then by a rename: new versions, red x white, x green, "
          "x white", near(first, (255, 0, 0, 255)) and near(second, (0, 0, 0, 255))
          and near(third, (255, 0, 0, 255)) and s["version"] == 3,
          "%s %s %s version %d" % (first, second, third, s["version"]))
    p.stop()

# A renderer that cannot start: the frames answer 503, the state says why
# (egl-gpu where there is no GPU; where there is one, the frame renders).
with Preview(pfx, "dot.yaml", "--renderer", "egl-gpu", cwd=work) as p:
    st, _, _ = p.get("/frame/0.png")
    s = p.state()
    check("a renderer that cannot start: 503, and the reason in the state",
          (st == 503 and "egl-gpu" in (s["render_error"] or "")) or
          (st == 200 and s["render_error"] is None), "%s %s" % (st, s.get("render_error")))
    p.stop()

# --host: another address, with a warning; Host may name it.
proc = subprocess.Popen([pfx, "preview", "dot.yaml", "--no-open", "--host", "127.0.0.2"], cwd=work,
                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
try:
    line = proc.stdout.readline().strip()
    m = re.match(r"^http://127\.0\.0\.2:(\d+)/\?token=([0-9a-f]{32})$", line)
    statuses = []
    if m:
        import http.client
        for host in ("127.0.0.2", "127.0.0.1", "evil.example"):
            c = http.client.HTTPConnection("127.0.0.2", int(m.group(1)), timeout=30)
            c.putrequest("GET", "/api/state?token=" + m.group(2), skip_host=True)
            c.putheader("Host", "%s:%s" % (host, m.group(1)))
            c.endheaders()
            statuses.append(c.getresponse().status)
            c.close()
finally:
    proc.terminate()
    err = proc.communicate(timeout=30)[1]
check("--host 127.0.0.2: its URL, a warning, Host checked against it",
      m and statuses == [200, 200, 403] and "warning: serving on 127.0.0.2, not 127.0.0.1" in err,
      "%r %s %r" % (line, statuses, err))

# A/B against another file (--compare, or POST /api/compare?file=) and
# another seed (?seed=): a second session under the same token, its frames
# at /frame/K.png?variant=compare, each the file pfx render writes for it.
with open(os.path.join(src, "tests/preview/dot.yaml")) as f:
    text = f.read()
for name, body in (("ab.yaml", text), ("other.yaml", text.replace("#ff0000", "#0000ff")),
                   ("seedy.yaml", text.replace("    speed: 0\n    lifetime: 100\n    size: 1.2",
                                               "    speed: 1\n    spread: 180\n    lifetime: 100\n    size: 0.3"))):
    with open(os.path.join(work, name), "w") as f:
        f.write(body)


def rendered(name, k, *args):
    out = os.path.join(work, "ab-" + name + "".join(args))
    subprocess.run([pfx, "render", name, "--frames", str(k), "-o", out, *args], cwd=work,
                   check=True, capture_output=True)
    with open(os.path.join(out, "%s_%04d.png" % (name[:-5], k)), "rb") as f:
        return f.read()


with Preview(pfx, "ab.yaml", "--compare", "other.yaml", cwd=work) as p:
    s = p.state()
    st, h, png = p.get("/frame/%d.png?variant=compare" % K)
    st0, _, png0 = p.get("/frame/%d.png" % K)
    cs = json.loads(p.get("/api/state?variant=compare")[2])
    check("--compare FILE: /api/state says so; ?variant=compare serves FILE's frame K (blue) as "
          "pfx render writes it, the edited file's stays red",
          s.get("compare") == {"file": "other.yaml", "seed": None} and st == st0 == 200 and
          png == rendered("other.yaml", K) and near(pixel(png, 48, 48), (0, 0, 255, 255)) and
          png0 == rendered("ab.yaml", K) and near(pixel(png0, 48, 48), (255, 0, 0, 255)) and
          cs["file"] == "other.yaml" and cs["version"] == 1,
          "%s %s %s %s" % (s.get("compare"), st, st0, cs.get("file")))
    edit(os.path.join(work, "other.yaml"), "#0000ff", "#ffffff")
    end = time.time() + 20
    while time.time() < end and json.loads(p.get("/api/state?variant=compare")[2])["version"] < 2:
        time.sleep(0.01)
    st, h, png = p.get("/frame/%d.png?variant=compare" % K)
    check("the compared file is watched: a save gives it version 2 (white)",
          st == 200 and h.get("X-Pfx-Version") == "2" and near(pixel(png, 48, 48), (255,) * 4),
          "%s %s %s" % (st, h.get("X-Pfx-Version"), pixel(png, 48, 48) if st == 200 else ""))
    st, _, body = p.get("/api/compare?file=missing.yaml", method="POST")
    st2, _, _ = p.get("/frame/0.png?variant=compare")
    check("POST /api/compare?file=missing: 400, one line, nothing compared (404)",
          st == 400 and st2 == 404 and
          body == b"pfx: cannot open 'missing.yaml': No such file or directory [PFX4002]\n",
          "%s %s %r" % (st, st2, body))
    st, _, _ = p.get("/api/compare?seed=x", method="POST")
    st2, _, _ = p.get("/api/compare?seed=7", method="GET")
    check("a seed that is not a number: 400; GET /api/compare: 404", st == 400 and st2 == 404,
          "%s %s" % (st, st2))
    p.stop()
# Pick on the comparison: its own emitters and lines (the compared file
# has three more lines above them), and 404 when nothing is compared.
with open(os.path.join(work, "shifted.yaml"), "w") as f:
    f.write("# one\n# two\n# three\n" + text)
with Preview(pfx, "ab.yaml", "--compare", "shifted.yaml", cwd=work) as p:
    def pick_of(variant):
        st, _, body = p.get("/pick?frame=%d&x=48&y=48%s" % (K, variant))
        return json.loads(body) if st == 200 else st
    a, b = pick_of(""), pick_of("&variant=compare")
    check("pick with ?variant=compare: the compared file's emitter and its own line",
          a == [{"emitter": "dot", "line": lines["dot"]}] and
          b == [{"emitter": "dot", "line": lines["dot"] + 3}], "%s %s" % (a, b))
    p.stop()
with Preview(pfx, "ab.yaml", cwd=work) as p:
    st, _, _ = p.get("/pick?frame=%d&x=48&y=48&variant=compare" % K)
    check("pick with ?variant=compare and nothing compared: 404", st == 404, str(st))
    p.stop()
with Preview(pfx, "seedy.yaml", cwd=work) as p:
    _, _, png0 = p.get("/frame/%d.png" % K)
    threads0 = p.threads()
    st, _, body = p.get("/api/compare?seed=7", method="POST")
    s = p.state()
    st1, _, png = p.get("/frame/%d.png?variant=compare" % K)
    check("POST /api/compare?seed=7: the same file at seed 7, as pfx render --seed 7 writes it",
          st == st1 == 200 and json.loads(body) == {"file": "seedy.yaml", "seed": 7} and
          s["compare"] == {"file": "seedy.yaml", "seed": 7} and
          png == rendered("seedy.yaml", K, "--seed", "7") and png0 == rendered("seedy.yaml", K) and
          png != png0, "%s %s %r" % (st, st1, body))
    st, _, body = p.get("/api/compare", method="POST")
    st2, _, _ = p.get("/frame/0.png?variant=compare")
    # The last holder of the comparison (a frame request finishing, or the
    # session's worker ending the step it is in) lets its threads go: on a
    # loaded machine that took longer than 0.2 s once in about 45 runs, so
    # the threads have 10 s to be gone.
    waited = 0
    while p.threads() > threads0 and waited < 200:
        time.sleep(0.05)
        waited += 1
    check("POST /api/compare with neither: compare with nothing, its threads gone",
          st == 200 and body == b"null" and st2 == 404 and p.state()["compare"] is None and
          p.threads() <= threads0, "%s %r %s %d > %d" % (st, body, st2, p.threads(), threads0))
    p.stop()

# Emitter tracks: bursts per emitter from the model's list, and the
# sub-emitter events each frame raised (the count the session records as it
# simulates): events.yaml's two shells die at 0.45 s, in frame 5 (0.4, 0.5].
shutil.copy(os.path.join(src, "tests/preview/events.yaml"), os.path.join(work, "events.yaml"))
with Preview(pfx, "events.yaml", cwd=work) as p:
    for k in range(10):
        p.get("/frame/%d.png" % k)
    s = p.state()
    events = [st and st.get("events") for st in s["stats"]]
    check("/api/state: bursts per emitter, and events per frame: 2 into spark in frame 5 only",
          [e["bursts"] for e in s["emitters"]] == [[0, 0.7], []] and
          events == [[0, 0]] * 5 + [[0, 2]] + [[0, 0]] * 4 and
          s["emitters"][0]["spawns"] == [{"event": "on_death", "emitter": "spark"}],
          "%s %s" % ([e["bursts"] for e in s["emitters"]], events))
    p.stop()

# A file name that is not UTF-8 (Latin-1 "caf\xe9.yaml", compared with
# "\xf6ther.yaml"): /api/state keeps its bytes as every JSON pfx writes does
# (pfx(1), File names in JSON): U+FFFD in "file", the bytes in
# "file_base64"; the same for the diagnostics text that quotes it, and for
# the compared file. It starts broken, so that the text names it.
latin, other = b"caf\xe9.yaml", b"\xf6ther.yaml"
with open(os.path.join(src, "tests/preview/dot.yaml")) as f:
    dot_text = f.read()
with open(os.path.join(os.fsencode(work), latin), "w") as f:
    f.write(dot_text.replace("    speed: 0\n", "    speed: [\n", 1))
shutil.copy(os.path.join(src, "tests/preview/dot.yaml"), os.path.join(os.fsencode(work), other))
with Preview(pfx, os.fsdecode(latin), "--compare", os.fsdecode(other), cwd=work) as p:
    st, _, body = p.get("/api/state")
    s = json.loads(body) if st == 200 else {}
    text = base64.b64decode(s.get("diagnostics_text_base64", ""))
    cmp = s.get("compare") or {}
    check("/api/state of a file named in Latin-1: U+FFFD for reading, its bytes in *_base64 "
          "(file, diagnostics_text, compare's file)",
          st == 200 and s["file"] == "caf\ufffd.yaml" and
          base64.b64decode(s.get("file_base64", "")) == latin and
          s["diagnostics_text"].startswith("caf\ufffd.yaml:") and text.startswith(latin + b":") and
          cmp.get("file") == "\ufffdther.yaml" and
          base64.b64decode(cmp.get("file_base64", "")) == other, "%s %r" % (st, body[:300]))
    news = s.get("news", 0)
    edit(os.path.join(os.fsencode(work), latin), "    speed: [\n", "    speed: 0\n")
    s = p.wait_news(news)
    st, _, png = p.get("/frame/0.png")
    check("the Latin-1 file, saved good: version 1, its frame 0 (red in the middle)",
          s["version"] == 1 and s["diagnostics"] == [] and st == 200 and
          near(pixel(png, 48, 48), (255, 0, 0, 255)),
          "%s %s %s %s" % (s["version"], st, s["diagnostics"], png and pixel(png, 48, 48)))
    p.stop()

# SIGKILL runs no cleanup: the scratch directory (named with the pid) of
# a killed preview is swept by the next one; a live process's is kept.
shm = "/dev/shm" if os.access("/dev/shm", os.W_OK) else os.environ.get("TMPDIR") or "/tmp"
live = os.path.join(shm, "pfx-preview-%d-abcdef" % os.getpid())
os.makedirs(live, exist_ok=True)
with Preview(pfx, "dot.yaml", cwd=work) as p:
    killed = [os.path.join(shm, d) for d in os.listdir(shm)
              if d.startswith("pfx-preview-%d-" % p.proc.pid)]
    st, _, _ = p.get("/frame/0.png")
    for d in killed:
        open(os.path.join(d, "v1_0001.png.tmp"), "w").write("half a frame")
    p.proc.kill()
    p.proc.wait()
left = [d for d in killed if os.path.exists(d)]
with Preview(pfx, "dot.yaml", cwd=work) as p:
    st2, _, _ = p.get("/frame/0.png")
    p.stop()
check("a preview killed by SIGKILL: its scratch dir is swept by the next, a live pid's kept",
      len(killed) == 1 and left == killed and st == st2 == 200 and
      not any(os.path.exists(d) for d in killed) and os.path.isdir(live),
      "%s %s %s %s" % (killed, left, st, st2))
shutil.rmtree(live, ignore_errors=True)

r = subprocess.run([pfx, "preview", "missing.yaml", "--no-open"], cwd=work, capture_output=True,
                   text=True, timeout=30)
check("a file that is not there: one line, exit 1, no URL",
      r.returncode == 1 and r.stdout == "" and
      r.stderr == "pfx: cannot open 'missing.yaml': No such file or directory [PFX4002]\n",
      "%d %r" % (r.returncode, r.stderr))
r = subprocess.run([pfx, "render", "dot.yaml", "--port", "1", "-o", "x"], cwd=work,
                   capture_output=True, text=True)
check("--port outside preview: usage error", r.returncode == 2 and "are for preview" in r.stderr,
      r.stderr)
sys.exit(0)
