"""End-to-end test of `cellmap serve` in a real browser: Debian's chromium,
headless, driven by the DevTools protocol over its pipe (fds 3 and 4,
messages of JSON ended by NUL), with the standard library alone.

  browser_test.py URL SHOTS_DIR

Opens the page at URL, waits for its tiles, and checks the screenshot's
pixels against the colours /cell gives at points well inside one label
(the label of the point's whole neighbourhood); pans by dragging the map
with the mouse and checks the move and that the tiles the new view needs
are drawn (the server computes them); zooms in with the wheel past one
pixel per cell, where tiles show the finer cells of refined levels;
clicks a point and checks the popup's cell against /cell and the orbit
drawn from the cell's centre. Exits non-zero with the reasons."""
import base64, json, os, shutil, subprocess, sys, tempfile, time, urllib.request

from pngcheck import read_png

WIDTH, HEIGHT = 1000, 800


class Browser:
    def __init__(self):
        exe = shutil.which("chromium") or shutil.which("chromium-browser")
        if not exe:
            sys.exit("chromium is not installed (Debian's chromium; .ci/install-deps installs it)")
        self.profile = tempfile.mkdtemp()
        to_r, self.to_w = os.pipe()
        self.from_r, from_w = os.pipe()

        def fds():  # the browser reads fd 3 and writes fd 4
            up_r, up_w = os.dup(to_r), os.dup(from_w)  # out of 3 and 4's way
            os.dup2(up_r, 3)
            os.dup2(up_w, 4)

        self.proc = subprocess.Popen(
            [exe, "--headless=new", "--no-sandbox", "--disable-gpu", "--remote-debugging-pipe",
             "--user-data-dir=" + self.profile, "--window-size=%d,%d" % (WIDTH, HEIGHT),
             "--no-first-run", "--disable-extensions", "about:blank"],
            preexec_fn=fds, close_fds=False, stdout=subprocess.DEVNULL,
            stderr=open(os.path.join(self.profile, "stderr"), "w"))
        os.close(to_r)
        os.close(from_w)
        self.next_id, self.buffer, self.events, self.session = 0, b"", [], None

    def send(self, method, params=None, session=True):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if session and self.session:
            msg["sessionId"] = self.session
        os.write(self.to_w, json.dumps(msg).encode() + b"\0")
        while True:
            reply = self.receive()
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError("%s: %s" % (method, reply["error"]))
                return reply.get("result", {})
            self.events.append(reply)

    def receive(self):
        while b"\0" not in self.buffer:
            chunk = os.read(self.from_r, 1 << 20)
            if not chunk:
                raise RuntimeError("the browser closed its pipe")
            self.buffer += chunk
        text, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(text)

    def open(self, url):
        target = self.send("Target.createTarget", {"url": "about:blank"}, session=False)
        self.session = self.send("Target.attachToTarget",
                                 {"targetId": target["targetId"], "flatten": True},
                                 session=False)["sessionId"]
        self.send("Emulation.setDeviceMetricsOverride",
                  {"width": WIDTH, "height": HEIGHT, "deviceScaleFactor": 1, "mobile": False})
        self.send("Page.enable")
        self.send("Page.navigate", {"url": url})

    def eval(self, expression):
        result = self.send("Runtime.evaluate", {"expression": expression, "returnByValue": True,
                                                "awaitPromise": True})
        if "exceptionDetails" in result:
            raise RuntimeError("%s: %s" % (expression, result["exceptionDetails"]))
        return result["result"].get("value")

    def wait(self, expression, what, seconds=60):
        end = time.time() + seconds
        while time.time() < end:
            try:
                if self.eval(expression):
                    return
            except RuntimeError:
                pass
            time.sleep(0.1)
        raise RuntimeError("timed out waiting for " + what)

    def tiles_loaded(self, base):
        """Waits until the visible tiles are drawn from the cluster as the
        server has it (the page draws them again after one grew it)."""
        end = time.time() + 120
        while time.time() < end:
            settled = self.eval("window.cellmapSettled === undefined ? -1 : window.cellmapSettled")
            loading = self.eval("document.querySelectorAll("
                                "'img.leaflet-tile:not(.leaflet-tile-loaded)').length")
            if loading == 0 and settled == get_json(base + "/info")["generation"]:
                time.sleep(0.5)  # Leaflet's fade-in
                return
            time.sleep(0.2)
        raise RuntimeError("timed out waiting for the tiles")

    def mouse(self, kind, x, y, **extra):
        params = {"type": kind, "x": x, "y": y, "button": "left", "clickCount": 1}
        params.update(extra)
        self.send("Input.dispatchMouseEvent", params)

    def drag(self, x0, y0, x1, y1, steps=100):
        """A drag in small steps: Leaflet starts a drag after the first step
        (which it does not move the map by), so the map moves by all but
        one step."""
        self.mouse("mousePressed", x0, y0)
        for k in range(1, steps + 1):
            self.mouse("mouseMoved", x0 + (x1 - x0) * k / steps, y0 + (y1 - y0) * k / steps,
                       buttons=1)
        time.sleep(0.3)  # still before the release: no inertia
        self.mouse("mouseReleased", x1, y1)

    def screenshot(self, path):
        data = base64.b64decode(self.send("Page.captureScreenshot", {"format": "png"})["data"])
        open(path, "wb").write(data)
        w, h, bpp, rows, _ = read_png(path)
        assert (w, h) == (WIDTH, HEIGHT), (w, h)
        return lambda x, y: tuple(rows[int(y)][int(x) * bpp:int(x) * bpp + 3])

    def close(self):
        try:
            self.send("Browser.close", session=False)
        except RuntimeError:
            pass
        self.proc.wait(timeout=30)
        shutil.rmtree(self.profile, ignore_errors=True)


def get_json(url):
    with urllib.request.urlopen(url, timeout=60) as r:
        return json.load(r)


def screen_point(b, x, y):
    p = b.eval("(() => { const p = cellmapMap.latLngToContainerPoint([%r, %r]);"
               " return [p.x, p.y]; })()" % (y, x))
    return p[0], p[1]


def latlng(b, sx, sy):
    return b.eval("(() => { const l = cellmapMap.containerPointToLatLng([%d, %d]);"
                  " return [l.lng, l.lat]; })()" % (sx, sy))


def check_colours(b, base, pixel, bad, what):
    """At a grid of screen points whose neighbourhood (3 pixels each way)
    has one label at the zoom shown (/cell), the pixel is the colour /cell
    gives that label."""
    zoom = b.eval("cellmapMap.getZoom()")
    ask = lambda sx, sy: get_json("%s/cell?x=%r&y=%r&zoom=%d&steps=0" %
                                  ((base,) + tuple(latlng(b, sx, sy)) + (zoom,)))
    checked = 0
    for sx in range(150, WIDTH - 150, 140):
        for sy in range(150, HEIGHT - 150, 120):
            centre = ask(sx, sy)
            labels = {centre["label"]} | {ask(sx + dx, sy + dy)["label"]
                                          for dx in (-3, 3) for dy in (-3, 3)}
            if len(labels) != 1:
                continue  # near a boundary
            checked += 1
            want = tuple(int(centre["colour"][i:i + 2], 16) for i in (1, 3, 5))
            if pixel(sx, sy) != want:
                bad.append("%s: pixel (%d, %d) is %s, %s (level %d) is %s" %
                           (what, sx, sy, pixel(sx, sy), centre["name"], centre["level"], want))
    if checked < 5:
        bad.append("%s: only %d points inside one label to check" % (what, checked))
    return checked


def main():
    base, shots = sys.argv[1].rstrip("/"), sys.argv[2]
    b = Browser()
    bad = []
    try:
        b.open(base + "/")
        b.tiles_loaded(base)
        pixel = b.screenshot(os.path.join(shots, "first.png"))
        n = check_colours(b, base, pixel, bad, "first view")
        print("first view: zoom %s, %d points checked" % (b.eval("cellmapMap.getZoom()"), n))

        # pan by dragging: the view moves by the drag, its new tiles are drawn
        before = b.eval("(() => { const c = cellmapMap.getCenter(); return [c.lng, c.lat]; })()")
        generation = get_json(base + "/info")["generation"]
        b.drag(700, 400, 200, 400)
        b.tiles_loaded(base)
        after = b.eval("(() => { const c = cellmapMap.getCenter(); return [c.lng, c.lat]; })()")
        x0, _ = screen_point(b, before[0], before[1])
        moved = (x0 - WIDTH / 2, screen_point(b, before[0], before[1])[1] - HEIGHT / 2)
        if abs(moved[0] + 495) > 1 or abs(moved[1]) > 1:
            bad.append("the drag by -500 px (less a step) moved the view by (%g, %g) px" % moved)
        info = get_json(base + "/info")
        if info["generation"] <= generation:
            bad.append("panning computed nothing (%d regions before, %d after)"
                       % (generation, info["generation"]))
        pixel = b.screenshot(os.path.join(shots, "panned.png"))
        n = check_colours(b, base, pixel, bad, "panned view")
        print("panned from %s to %s: %d regions, %d points checked"
              % (before, after, info["generation"], n))

        # zoom in past one pixel per cell: zoom-0 tiles magnified, same colours
        for _ in range(3):  # 60 px of wheel a zoom level (Leaflet's wheelPxPerZoomLevel)
            b.send("Input.dispatchMouseEvent", {"type": "mouseWheel", "x": 500, "y": 400,
                                                "deltaX": 0, "deltaY": -60})
            time.sleep(0.6)
            b.tiles_loaded(base)
        zoom = b.eval("cellmapMap.getZoom()")
        shown = get_json("%s/cell?x=%r&y=%r&zoom=%d&steps=0" %
                         ((base,) + tuple(latlng(b, 500, 400)) + (zoom,)))
        if zoom <= 0 or shown["level"] != min(zoom, get_json(base + "/info")["max_level"]):
            bad.append("the wheel zoomed to %s, cells of level %d shown" % (zoom, shown["level"]))
        pixel = b.screenshot(os.path.join(shots, "zoomed.png"))
        n = check_colours(b, base, pixel, bad, "zoomed in")
        print("zoomed in to %s: %d points checked" % (zoom, n))

        # a click: the popup names the cell /cell gives, the orbit starts at
        # its centre (the popup closed for the screenshot; the orbit stays)
        cx, cy = 430, 520
        ll = latlng(b, cx, cy)
        cell = get_json("%s/cell?x=%r&y=%r&zoom=%d&steps=0" % (base, ll[0], ll[1],
                                                             b.eval("cellmapMap.getZoom()")))
        ox, oy = screen_point(b, cell["centre"][0], cell["centre"][1])
        near = lambda p: [(x, y) for x in range(int(ox) - 2, int(ox) + 3)
                          for y in range(int(oy) - 2, int(oy) + 3) if sum(p(x, y)) < 200]
        quiet = near(pixel)
        b.mouse("mousePressed", cx, cy)
        b.mouse("mouseReleased", cx, cy)
        b.wait("document.querySelector('.leaflet-popup-content') !== null", "the popup")
        b.wait("document.querySelectorAll('path.leaflet-interactive').length > 0", "the orbit")
        text = b.eval("document.querySelector('.leaflet-popup-content').textContent")
        if not text.startswith("cell " + ", ".join(map(str, cell["cell"]))):
            bad.append("the popup says '%s', /cell says cell %s" % (text, cell["cell"]))
        b.eval("cellmapMap.closePopup(), 0")
        time.sleep(0.5)
        pixel = b.screenshot(os.path.join(shots, "clicked.png"))
        if quiet or not near(pixel):
            bad.append("no orbit drawn from the clicked cell's centre (%d dark pixels there "
                       "before the click, %d after)" % (len(quiet), len(near(pixel))))
        print("clicked (%d, %d): %s" % (cx, cy, text))
    except RuntimeError as e:
        bad.append(str(e))
    finally:
        b.close()
    if bad:
        sys.exit("\n".join(bad))


if __name__ == "__main__":
    main()
