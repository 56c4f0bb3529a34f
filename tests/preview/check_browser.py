"""pfx preview in a real browser (Debian's chromium, headless, through
selenium): the page shows frame K as `pfx render --frames K` draws it; a
colour edit shows the new colour, a typo its diagnostic at line:col while
the last good frames keep playing, the fix clears it; stepping, scrubbing,
the emitter tracks, pick and A/B; the latency from a save to the new frame
shown. Usage: check_browser.py PFX SRC WORK [--screenshot OUT.png]
[--bench EFFECT.yaml...]; prints one `ok`/`FAIL` line a check, and `#`
lines with the figures."""
import base64
import io
import os
import shutil
import subprocess
import sys
import time

from PIL import Image
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select

sys.path.insert(0, os.path.dirname(__file__))
from preview import Preview, edit, line_of  # noqa: E402

pfx, src, work = sys.argv[1:4]
rest = sys.argv[4:]
screenshot = rest[rest.index("--screenshot") + 1] if "--screenshot" in rest else None
bench = rest[rest.index("--bench") + 1:] if "--bench" in rest else []
failures = 0


def check(name, ok, detail=""):
    global failures
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + str(detail)))
    failures += not ok


def browser():
    o = webdriver.ChromeOptions()
    o.binary_location = "/usr/bin/chromium"
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              "--window-size=1440,900", "--force-device-scale-factor=1"):
        o.add_argument(a)
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=o)


def wait(d, js, timeout=30):
    """The value of the JS expression once truthy; None after timeout."""
    end = time.time() + timeout
    while time.time() < end:
        v = d.execute_script("try { return " + js + "; } catch (e) { return null; }")
        if v:
            return v
        time.sleep(0.01)
    return None


def canvas(d):
    """The canvas's pixels as a PIL image, read back from the page."""
    url = d.execute_script("return document.getElementById('view').toDataURL('image/png')")
    return Image.open(io.BytesIO(base64.b64decode(url.split(",", 1)[1]))).convert("RGBA")


def near(p, want, tol=3):
    return all(abs(a - b) <= tol for a, b in zip(p, want))


def save_latency(d, p, path, old, new):
    """Edits the file and returns ms from the save to the new version's
    frame under the playhead drawn in the page (window.pfxShown)."""
    v = d.execute_script("return window.pfx.state.version")
    t0 = time.time() * 1000
    edit(path, old, new)
    shown = wait(d, "window.pfxShown && window.pfxShown.version > %d && window.pfxShown" % v)
    return shown["at"] - t0 if shown else None


def main_checks(d):
    dot = os.path.join(work, "dot.yaml")
    shutil.copy(os.path.join(src, "tests/preview/dot.yaml"), dot)
    K = 5
    with Preview(pfx, "dot.yaml", cwd=work) as p:
        d.get(p.url)
        ok = wait(d, "window.pfx.state && window.pfx.state.version === 1 && window.pfxShown")
        check("the page loads and shows version 1", ok, d.page_source[:200])
        d.execute_script("window.pfx.seek(%d)" % K)
        Select(d.find_element(By.ID, "bg")).select_by_value("black")
        ok = wait(d, "window.pfx.shown && window.pfx.shown.frame === %d" % K)
        time.sleep(0.2)
        subprocess.run([pfx, "render", "dot.yaml", "--frames", str(K), "-o", "r", "-q"],
                       cwd=work, check=True)
        want = Image.open(os.path.join(work, "r/dot_%04d.png" % K)).convert("RGBA")
        got = canvas(d)
        diff = max(max(abs(a - b) for a, b in zip(pa, pb))
                   for pa, pb in zip(got.getdata(), want.getdata())) if got.size == want.size else 999
        check("the page's canvas shows frame K as pfx render --frames K draws it",
              ok and diff <= 1, "size %s, largest difference %d" % (got.size, diff))
        check("frame K in the page: red middle, green right, black corner",
              near(got.getpixel((48, 48)), (255, 0, 0, 255))
              and near(got.getpixel((79, 48)), (0, 255, 0, 255))
              and near(got.getpixel((2, 2)), (0, 0, 0, 255)), got.getpixel((48, 48)))
        status = wait(d, "document.getElementById('status').textContent === "
                      "'all 10 frames rendered' && 'ok'", 30)
        check("the header says when every frame is rendered", status,
              d.find_element(By.ID, "status").text)
        clock = d.find_element(By.ID, "clock").text
        check("the clock shows frame and seconds", clock.startswith("5 / 9") and "0.500 s" in clock,
              clock)

        # A colour edit: the new colour, without reloading the page.
        d.execute_script("window.pfxMarker = 1")
        ms = save_latency(d, p, dot, '"#ff0000"', '"#0000ff"')
        time.sleep(0.1)
        c = canvas(d)
        check("an edit of a colour shows the new colour without a reload",
              ms is not None and near(c.getpixel((48, 48)), (0, 0, 255, 255))
              and d.execute_script("return window.pfxMarker") == 1
              and d.execute_script("return window.pfx.frame") == K, c.getpixel((48, 48)))
        print("# latency save -> new frame shown, dot.yaml 96x96: %.0f ms" % (ms or -1))

        # A/B: version 1 (red) against version 2 (blue).
        Select(d.find_element(By.ID, "ab")).select_by_value("side")
        time.sleep(0.2)
        c = canvas(d)
        check("A/B side by side: the last version left, the current right",
              c.size == (192, 96) and near(c.getpixel((48, 48)), (255, 0, 0, 255))
              and near(c.getpixel((96 + 48, 48)), (0, 0, 255, 255)), (c.size, c.getpixel((48, 48))))
        Select(d.find_element(By.ID, "ab")).select_by_value("diff")
        time.sleep(0.2)
        c = canvas(d)
        check("A/B difference: |red - blue| in the middle, black where equal",
              near(c.getpixel((48, 48)), (255, 0, 255, 255))
              and near(c.getpixel((79, 48)), (0, 0, 0, 255)), c.getpixel((48, 48)))
        # A pinned version stays A: pin version 2 (blue), save green (3),
        # then red (4): A is still blue, B red.
        d.find_element(By.ID, "pin").click()
        Select(d.find_element(By.ID, "ab")).select_by_value("side")
        for old, new, v in (('"#0000ff"', '"#00ff00"', 3), ('"#00ff00"', '"#ff0000"', 4)):
            edit(dot, old, new)
            wait(d, "window.pfxShown && window.pfxShown.version === %d" % v)
        time.sleep(0.2)
        c = canvas(d)
        check("A/B with version 2 pinned: blue against version 4's red",
              near(c.getpixel((48, 48)), (0, 0, 255, 255))
              and near(c.getpixel((96 + 48, 48)), (255, 0, 0, 255)),
              (c.getpixel((48, 48)), c.getpixel((96 + 48, 48))))
        d.find_element(By.ID, "pin").click()
        edit(dot, '"#ff0000"', '"#0000ff"')
        wait(d, "window.pfxShown && window.pfxShown.version === 5")
        time.sleep(0.2)
        c = canvas(d)
        check("A/B unpinned: the last version (4, red) against the current (5, blue)",
              near(c.getpixel((48, 48)), (255, 0, 0, 255))
              and near(c.getpixel((96 + 48, 48)), (0, 0, 255, 255)),
              (c.getpixel((48, 48)), c.getpixel((96 + 48, 48))))
        Select(d.find_element(By.ID, "ab")).select_by_value("off")

        # A typo: the diagnostic at its line:col; the last good frames play on.
        d.find_element(By.ID, "play").click()
        edit(dot, "size: 1.2", "size: 1.2.")
        line = line_of(dot, "size: 1.2.")
        col = open(dot).read().splitlines()[line - 1].index("1.2.") + 1
        text = wait(d, "document.getElementById('diag').textContent.includes('dot.yaml:%d:%d: error')"
                    " && document.getElementById('diag').textContent" % (line, col))
        v = subprocess.run([pfx, "validate", "dot.yaml"], cwd=work, capture_output=True, text=True)
        check("a typo shows its diagnostic at line:col, as validate prints it",
              text and text.strip() == v.stderr.strip(), repr(text))
        stale = d.find_element(By.ID, "stale").is_displayed()
        f0 = d.execute_script("return window.pfx.frame")
        moved = wait(d, "window.pfx.frame !== %d" % f0, 5)
        c = canvas(d)
        check("a typo: the last good frames keep playing under a banner",
              stale and moved and near(c.getpixel((48, 48)), (0, 0, 255, 255)),
              (stale, moved, c.getpixel((48, 48))))
        edit(dot, "size: 1.2.", "size: 1.2")
        ok = wait(d, "document.getElementById('diag').textContent === 'No problems.' && "
                  "window.pfx.state.version === 6")
        check("the fix clears the diagnostic", ok and not d.find_element(By.ID, "stale").is_displayed())

        # Stepping and scrubbing.
        d.find_element(By.ID, "play").click()  # pause
        d.execute_script("window.pfx.seek(3)")
        d.find_element(By.ID, "next").click()
        a = d.execute_script("return window.pfx.frame")
        d.find_element(By.ID, "prev").click()
        d.find_element(By.ID, "prev").click()
        b = d.execute_script("return window.pfx.frame")
        check("stepping: next and previous frame", a == 4 and b == 2, (a, b))
        ruler = d.find_element(By.ID, "ruler")
        ActionChains(d).move_to_element_with_offset(ruler, int(ruler.size["width"] * 0.25), 0) \
            .click().perform()
        f = d.execute_script("return window.pfx.frame")
        check("scrubbing the timeline to 3/4 shows frame 7", f == 7, f)

        # The tracks: one per emitter with its line, the bursts as ticks.
        names = [e.text for e in d.find_elements(By.CSS_SELECTOR, ".track .name")]
        ticks = d.find_elements(By.CSS_SELECTOR, ".track .tick")
        check("a track per emitter, named with its line, its burst a tick at 0",
              names == ["dot :%d" % line_of(dot, "  dot:"), "side :%d" % line_of(dot, "  side:")]
              and len(ticks) == 2 and all(t.value_of_css_property("left") == "0px" for t in ticks),
              names)

        # A renamed emitter: the tracks follow (the frame count is the same).
        edit(dot, "  side:", "  glow:")
        names = wait(d, "[...document.querySelectorAll('.track .name')].map((e) => e.textContent)"
                     ".join(',').includes('glow') && [...document.querySelectorAll('.track .name')]"
                     ".map((e) => e.textContent)", 20)
        check("an emitter renamed: its track follows", names == ["dot :%d" % line_of(dot, "  dot:"),
                                                                 "glow :%d" % line_of(dot, "  glow:")],
              names)

        # Pick: click the middle of the picture.
        d.find_element(By.ID, "fit").click()  # 1:1, so that a CSS pixel is a frame pixel
        view = d.find_element(By.ID, "view")
        ActionChains(d).move_to_element_with_offset(view, 0, 0).click().perform()
        item = wait(d, "document.querySelector('#pick li') && "
                    "document.querySelector('#pick li').textContent.startsWith('dot') && "
                    "document.querySelector('#pick li').textContent")
        check("pick: the middle pixel names dot and its line",
              item == "dotdot.yaml:%d" % line_of(dot, "  dot:"), item)
        return p.stop()


def alpha_checks(d):
    """A half-transparent red disc over a white page background, from
    straight and from premultiplied PNGs: both must show the same colour,
    C a + (1 - a) white, which a premultiplied PNG drawn as straight misses
    (127 x 0.5 + 255 x 0.5 = 191 in red)."""
    half = os.path.join(work, "half.yaml")
    with open(os.path.join(src, "tests/preview/dot.yaml")) as f:
        text = f.read()
    with open(half, "w") as f:
        f.write(text.replace('background: "#000000"', "background: transparent")
                .replace('"#ff0000"', '"#ff000080"'))
    for alpha in ("straight", "premultiplied"):
        with Preview(pfx, "half.yaml", "--alpha", alpha, cwd=work) as p:
            d.get(p.url)
            wait(d, "window.pfx.state && window.pfx.state.version === 1")
            d.execute_script("window.pfx.seek(5)")
            Select(d.find_element(By.ID, "bg")).select_by_value("white")
            wait(d, "window.pfx.shown && window.pfx.shown.frame === 5")
            time.sleep(0.3)
            c = canvas(d)
            check("%s alpha over white: (255, 127, 127) in the middle, white outside" % alpha,
                  near(c.getpixel((48, 48)), (255, 127, 127, 255), 4)
                  and near(c.getpixel((2, 2)), (255, 255, 255, 255), 1),
                  (c.getpixel((48, 48)), c.getpixel((2, 2))))
            p.stop()


def compare_checks(d):
    """A/B against another file (--compare, and typed in the page) and
    another seed (typed in the page): side by side and the difference."""
    dot = os.path.join(work, "dot.yaml")
    shutil.copy(os.path.join(src, "tests/preview/dot.yaml"), dot)
    with open(dot) as f:
        text = f.read()
    with open(os.path.join(work, "blue.yaml"), "w") as f:
        f.write(text.replace("#ff0000", "#0000ff"))
    with open(os.path.join(work, "white.yaml"), "w") as f:
        f.write(text.replace("#ff0000", "#ffffff"))
    with open(os.path.join(work, "seedy.yaml"), "w") as f:
        f.write(text.replace("    speed: 0\n    lifetime: 100\n    size: 1.2",
                             "    speed: 1\n    spread: 180\n    lifetime: 100\n    size: 0.3"))
    K = 5
    with Preview(pfx, "dot.yaml", "--compare", "blue.yaml", cwd=work) as p:
        d.get(p.url)
        wait(d, "window.pfx.state && window.pfx.state.version === 1 && window.pfxShown")
        d.execute_script("window.pfx.seek(%d)" % K)
        Select(d.find_element(By.ID, "bg")).select_by_value("black")
        ok = wait(d, "window.pfx.compareFrames.has(%d) && window.pfx.shown.frame === %d" % (K, K))
        time.sleep(0.2)
        c = canvas(d)
        check("--compare blue.yaml: the page opens side by side, blue.yaml (A) left, the file right",
              ok and d.find_element(By.ID, "ab").get_attribute("value") == "side" and
              c.size == (192, 96) and near(c.getpixel((48, 48)), (0, 0, 255, 255)) and
              near(c.getpixel((96 + 48, 48)), (255, 0, 0, 255)),
              (ok, c.size, c.getpixel((48, 48)), c.getpixel((96 + 48, 48))))
        # Pick on the left half (A): the compared file's emitter, in its file.
        d.find_element(By.ID, "fit").click()  # 1:1, so that a CSS pixel is a frame pixel
        view = d.find_element(By.ID, "view")
        ActionChains(d).move_to_element_with_offset(view, -48, 0).click().perform()
        item = wait(d, "document.querySelector('#pick li') && "
                    "document.querySelector('#pick li').textContent.includes('blue.yaml') && "
                    "document.querySelector('#pick li').textContent", 10)
        check("side by side, a pick on A names the compared file's emitter and line",
              item == "dotblue.yaml:%d" % line_of(dot, "  dot:"), item)
        d.find_element(By.ID, "fit").click()
        Select(d.find_element(By.ID, "ab")).select_by_value("diff")
        time.sleep(0.2)
        c = canvas(d)
        check("against a file, difference: |blue - red| in the middle, black where equal",
              near(c.getpixel((48, 48)), (255, 0, 255, 255)) and
              near(c.getpixel((79, 48)), (0, 0, 0, 255)), c.getpixel((48, 48)))
        # Another file, typed in the page.
        Select(d.find_element(By.ID, "ab")).select_by_value("wipe")
        box = d.find_element(By.ID, "against-file")
        box.clear()
        box.send_keys("white.yaml\n")
        ok = wait(d, "window.pfx.compare && window.pfx.compare.file === 'white.yaml' && "
                  "window.pfx.compareFrames.has(%d)" % K)
        d.execute_script("document.getElementById('wipe-handle').hidden = true")
        time.sleep(0.3)
        c = canvas(d)
        check("a file typed in the page, wipe at the middle: white left of it, red right",
              ok and near(c.getpixel((47, 48)), (255, 255, 255, 255)) and
              near(c.getpixel((48, 48)), (255, 0, 0, 255)),
              (ok, c.getpixel((47, 48)), c.getpixel((48, 48))))
        box.clear()
        box.send_keys("nothere.yaml\n")
        err = wait(d, "document.getElementById('against-error').textContent")
        check("a file that is not there: the server's one line in the page",
              err == "pfx: cannot open 'nothere.yaml': No such file or directory [PFX4002]\n", err)
        p.stop()
    with Preview(pfx, "seedy.yaml", cwd=work) as p:
        d.get(p.url)
        wait(d, "window.pfx.state && window.pfx.state.version === 1 && window.pfxShown")
        d.execute_script("window.pfx.seek(%d)" % K)
        Select(d.find_element(By.ID, "bg")).select_by_value("black")
        Select(d.find_element(By.ID, "against")).select_by_value("seed")
        box = d.find_element(By.ID, "against-seed")
        box.send_keys("7\n")
        ok = wait(d, "window.pfx.compare && window.pfx.state.compare && "
                  "window.pfx.state.compare.seed === 7 && window.pfx.compareFrames.has(%d) && "
                  "window.pfx.shown.frame === %d" % (K, K))
        time.sleep(0.3)
        c = canvas(d)
        for seed in ("1", "7"):
            subprocess.run([pfx, "render", "seedy.yaml", "--frames", str(K), "-o", "s" + seed,
                            "--seed", seed, "-q"], cwd=work, check=True)
        a = Image.open(os.path.join(work, "s7/seedy_%04d.png" % K)).convert("RGBA")
        b = Image.open(os.path.join(work, "s1/seedy_%04d.png" % K)).convert("RGBA")
        left, right = c.crop((0, 0, 96, 96)), c.crop((96, 0, 192, 96))
        dl = max(max(abs(x - y) for x, y in zip(pa, pb)) for pa, pb in zip(left.getdata(), a.getdata()))
        dr = max(max(abs(x - y) for x, y in zip(pa, pb)) for pa, pb in zip(right.getdata(), b.getdata()))
        check("seed 7 typed in the page: left is pfx render --seed 7, right the file's seed",
              ok and c.size == (192, 96) and dl <= 1 and dr <= 1 and a.tobytes() != b.tobytes(),
              (ok, c.size, dl, dr))
        p.stop()


def events_checks(d):
    """The emitter tracks: bursts as ticks at their times, and the frames
    where a parent's sub-emitter events fire marked on its lane."""
    shutil.copy(os.path.join(src, "tests/preview/events.yaml"), os.path.join(work, "events.yaml"))
    with Preview(pfx, "events.yaml", cwd=work) as p:
        d.get(p.url)
        ok = wait(d, "window.pfx.state && window.pfx.state.stats.every((s) => s && s.events)", 60)
        time.sleep(0.3)
        lanes = d.find_elements(By.CSS_SELECTOR, ".track .lane")
        width = lanes[0].size["width"]
        ticks = [round(t.location["x"] - lanes[0].location["x"])
                 for t in lanes[0].find_elements(By.CLASS_NAME, "tick")]
        marks = [(m.get_attribute("data-first"), m.get_attribute("data-last"),
                  round(m.location["x"] - lanes[0].location["x"]), m.get_attribute("title"))
                 for m in lanes[0].find_elements(By.CLASS_NAME, "event")]
        others = lanes[1].find_elements(By.CLASS_NAME, "event")
        check("tracks: shell's bursts as ticks at 0 and 0.7 s; its on_death events marked at "
              "frame 5 (half the lane), spark's lane unmarked",
              ok and ticks == [0, round(0.7 * width)] and len(marks) == 1 and
              marks[0][:3] == ("5", "5", round(0.5 * width)) and
              marks[0][3].startswith("2 sub-emitter events (on death") and not others,
              (ok, ticks, width, marks, len(others)))
        p.stop()


def take_screenshot(d, out):
    """The page over a real example that reads at a glance (campfire:
    flames, smoke, sparks, a track each), paused mid-effect after a pick on
    the flames, every frame rendered so the tracks are whole."""
    eff = os.path.join(work, "shot")
    shutil.copytree(os.path.join(src, "effects"), eff, dirs_exist_ok=True)
    with Preview(pfx, "campfire.yaml", cwd=eff) as p:
        d.get(p.url)
        wait(d, "window.pfx.state && window.pfx.state.version === 1")
        wait(d, "window.pfx.state.stats.every((s) => s)", 300)
        k = p.state()["frames"] * 40 // 100
        d.execute_script("window.pfx.seek(%d)" % k)
        wait(d, "window.pfx.shown && window.pfx.shown.frame === %d" % k, 60)
        view = d.find_element(By.ID, "view")
        ActionChains(d).move_to_element_with_offset(view, 0, view.size["height"] // 10).click().perform()
        time.sleep(1.5)
        d.save_screenshot(out)
        p.stop()


def cpu_ms(pid):
    """CPU time the process has used (all its threads), ms."""
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) * 1000.0 / os.sysconf("SC_CLK_TCK")


def run_bench(d, effects):
    """ms from save to the new frame shown, per example at 512x512, with the
    playhead mid-effect: the median of five saves, and the CPU time pfx
    spent on each (which a loaded machine does not stretch)."""
    for path in effects:
        name = os.path.basename(path)
        eff = os.path.join(work, "bench")
        shutil.copytree(os.path.dirname(os.path.abspath(path)), eff, dirs_exist_ok=True)
        with Preview(pfx, name, "--size", "512x512", cwd=eff) as p:
            d.get(p.url)
            wait(d, "window.pfx.state && window.pfx.state.version === 1")
            k = p.state()["frames"] // 2
            d.execute_script("window.pfx.seek(%d)" % k)
            wait(d, "window.pfx.shown && window.pfx.shown.frame === %d" % k, 120)
            times, cpu = [], []
            for i in range(5):
                time.sleep(1.0)  # the prefetch of the frames after the playhead
                c0 = cpu_ms(p.proc.pid)
                ms = save_latency(d, p, os.path.join(eff, name), "\n", "\n# edit %d\n" % i)
                cpu.append(cpu_ms(p.proc.pid) - c0)
                times.append(ms if ms is not None else float("inf"))
            times.sort()
            cpu.sort()
            print("# %-22s frame %3d: %6.0f ms wall (median of 5; %.0f to %.0f), %4.0f ms CPU"
                  % (name, k, times[2], times[0], times[-1], cpu[2]), flush=True)
            p.stop()


d = browser()
try:
    if bench:
        run_bench(d, bench)
    else:
        status = main_checks(d)
        check("the server stops cleanly after the browser session", status == 0, status)
        alpha_checks(d)
        compare_checks(d)
        events_checks(d)
        if screenshot:
            take_screenshot(d, screenshot)
            print("# screenshot: %s" % screenshot)
finally:
    d.quit()
