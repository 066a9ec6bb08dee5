#!/usr/bin/env python3
"""Drives lensview's web page in headless Chromium over the DevTools
protocol (or, --browser firefox, in headless Firefox over WebDriver BiDi:
tools/web_bidi.py; --browser webkit, in WebKitGTK's MiniBrowser, Safari's
engine, over WebDriver: tools/web_webkit.py), for tests/web.rs (and the
figures of docs/web.md).

Serves DIST on 127.0.0.1 (a thread of this process, web/serve.py's server;
with the COOP/COEP headers unless --no-isolation), starts Chromium with a
new profile, opens the page with QUERY, waits for the finished picture and
writes what it saw into OUT:
  first.rgba       the canvas's RGBA bytes
  moved.rgba/.toml after pressing W: the canvas, and the page's scene file
  lens.rgba/.toml  then after the lens key 2 (lens d +): the same
  looked.rgba/.toml then after mouse-look by (40, -10) pixels (then back)
  panel.rgba/.toml then after typing r1 = PANEL_R1 and Enter in the panel
  panel-error.txt  the page's error line after typing r1 = PANEL_BAD
  undone.rgba      the canvas after Ctrl+Z (the r1 edit undone)
  redone.rgba      the canvas after the panel's Redo button
  glass.rgba/.toml then after picking the glass PANEL_GLASS in the panel
  saved.toml/.png  what the page's Save buttons downloaded then
  optics.png       a screenshot after F6 and F7 (the optics overlay and the
                   analysis panel), then the field set to 5°
  added.rgba/.toml then after picking a sphere in the panel's Add menu
  deleted.rgba/.toml then after its Delete button (the sphere selected)
  undeleted.rgba   then after the Undo button
  error.txt        the page's error line after opening BAD with its file input
  dropped.txt      the same after dropping BAD on the page
  good.rgba        the canvas after dropping GOOD on the page then
  preset-NAME.rgba each preset of --presets opened with ?scene=NAME&PRESET_QUERY
  report.json      times, sizes, threads and every console error or exception
--measure: only the first picture (no key, no file; with --optics, then
F6 and F7 and the screenshot). Exits 0 when the page
ran; the caller judges the pictures. Chromium and the server are stopped
on every exit (and the caller kills the process group on a timeout)."""

import argparse
import base64
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "web"))
import serve  # noqa: E402

try:
    import websocket  # websocket-client, from PyPI
except ImportError:
    sys.exit("error: Python's websocket-client is missing: python3 -m pip install websocket-client (.ci/run does)")
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import web_bidi  # noqa: E402
from web_page_base import SocketPage  # noqa: E402
import web_webkit  # noqa: E402

FLAGS = [
    "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
    "--disable-component-update", "--disable-sync", "--no-first-run", "--no-default-browser-check",
    "--remote-debugging-port=0", "--remote-debugging-address=127.0.0.1", "--window-size=1400,1000",
]


class Page(SocketPage):
    """One DevTools connection to a page: commands, and the events seen."""

    def __init__(self, ws_url):
        super().__init__(websocket.create_connection(ws_url, timeout=60, suppress_origin=True))

    @staticmethod
    def failure(msg):
        return msg.get("error")

    def event(self, msg):
        m, p = msg.get("method"), msg.get("params", {})
        if m == "Runtime.exceptionThrown":
            d = p["exceptionDetails"]
            self.errors.append("exception: " + d.get("exception", {}).get("description", d.get("text", "")))
        elif m == "Runtime.consoleAPICalled" and p["type"] in ("error", "assert"):
            self.errors.append("console.error: " + " ".join(str(a.get("value", a.get("description"))) for a in p["args"]))
        elif m == "Log.entryAdded" and p["entry"]["level"] == "error":
            self.errors.append("log: " + p["entry"]["text"])

    def eval(self, expr):
        r = self.call("Runtime.evaluate", expression=expr, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in r:
            raise RuntimeError(f"{expr}: {r['exceptionDetails']}")
        return r["result"].get("value")

    def navigate(self, url):
        self.call("Page.navigate", url=url)

    def key(self, code, key, vk, modifiers=0):
        """One key pressed and released, as the keyboard sends it (a
        character key types its character; F6, or with Ctrl, none)."""
        types = len(key) == 1 and not modifiers
        for kind in ("keyDown", "keyUp"):
            self.call("Input.dispatchKeyEvent", type=kind, code=code, key=key, windowsVirtualKeyCode=vk,
                      modifiers=modifiers, **({"text": key} if kind == "keyDown" and types else {}))

    def close(self):
        pass


def canvas(page):
    """The picture's canvas as RGBA bytes."""
    b64 = page.eval("""(() => {
        const c = document.getElementById('view');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let s = '';
        for (let i = 0; i < d.length; i += 0x8000) s += String.fromCharCode.apply(null, d.subarray(i, i + 0x8000));
        return btoa(s);
    })()""")
    return base64.b64decode(b64)


def start_chromium(profile):
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if not exe:
        sys.exit("error: chromium is missing: apt-get install chromium (.ci/run does)")
    proc = subprocess.Popen([exe, *FLAGS, f"--user-data-dir={profile}", "about:blank"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    port_file = os.path.join(profile, "DevToolsActivePort")
    for _ in range(300):
        if os.path.exists(port_file):
            with open(port_file) as f:
                port = f.readline().strip()
            if port:
                return proc, int(port)
        if proc.poll() is not None:
            sys.exit(f"error: chromium exited at start (status {proc.returncode})")
        time.sleep(0.1)
    proc.kill()
    sys.exit("error: chromium did not open its DevTools port in 30 s")


def page_target(port):
    for _ in range(100):
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as r:
            pages = [t for t in json.load(r) if t["type"] == "page"]
        if pages:
            return pages[0]["webSocketDebuggerUrl"]
        time.sleep(0.1)
    raise RuntimeError("chromium shows no page")


STATE = "JSON.stringify(window.lensview)"


def open_page(page, url, a):
    """Opens `url` and waits for its finished first picture (or an error);
    returns the page's state and the wall time it took. The page before is
    left for about:blank first, so that its workers (the render worker and
    its thread pool) are gone before the new page starts its own."""
    page.navigate("about:blank")
    t0 = time.monotonic()
    page.navigate(url)
    page.wait("window.lensview && (window.lensview.done || window.lensview.error !== '')", "its first picture", a.timeout)
    return json.loads(page.eval(STATE)), time.monotonic() - t0


def save(out, name, data):
    with open(os.path.join(out, name), "wb" if isinstance(data, bytes) else "w") as f:
        f.write(data)


def press(page, a, code, key, vk, renders, what):
    """Presses a key on the focused canvas as a user does; waits for the
    finished picture it starts (the page's `renders`-th)."""
    page.eval("document.getElementById('view').focus()")
    page.key(code, key, vk)
    page.wait(f"window.lensview.renders >= {renders} && window.lensview.done", what, a.timeout)
    return json.loads(page.eval(STATE))


def light_key(page, a, out, report):
    """The desktop's light key L: the scene file before and the picture
    and file after."""
    save(out, "unlit.toml", page.eval("window.lensview.sceneToml()"))
    renders = json.loads(page.eval(STATE))["renders"]
    report["light"] = press(page, a, "KeyL", "l", 76, renders + 1, "the picture after the light key L")
    save(out, "light.rgba", canvas(page))
    save(out, "light.toml", page.eval("window.lensview.sceneToml()"))


def type_field(page, key, text):
    """Types `text` into the panel's field `key` (replacing it) and Enter."""
    page.eval(f"(() => {{ const i = document.getElementById('field-{key}'); i.focus(); i.select(); }})()")
    page.call("Input.insertText", text=text)
    for kind in ("keyDown", "keyUp"):
        page.call("Input.dispatchKeyEvent", type=kind, code="Enter", key="Enter", windowsVirtualKeyCode=13,
                  **({"text": "\r"} if kind == "keyDown" else {}))


def panel_edits(page, a, out, report):
    """The panel: the lens selected, r1 typed, a refused r1, Ctrl+Z, Redo."""
    state = json.loads(page.eval(STATE))
    renders, panels = state["renders"], state.get("panels", 0)
    page.eval("""(() => { const s = document.getElementById('items');
        s.value = 'lens:0'; s.dispatchEvent(new Event('change')); })()""")
    # The panel the worker sends for the selection (the lens may be shown
    # already: a panel arriving later would rebuild the field being typed).
    page.wait(f"window.lensview.panels > {panels} && window.lensview.panel.selected === 'lens:0'"
              " && !!document.getElementById('field-r1')", "the lens in the panel", a.timeout)
    type_field(page, "r1", a.panel_r1)
    page.wait(f"window.lensview.renders >= {renders + 1} && window.lensview.done", "the picture after r1", a.timeout)
    report["panel"] = json.loads(page.eval(STATE))
    save(out, "panel.rgba", canvas(page))
    save(out, "panel.toml", page.eval("window.lensview.sceneToml()"))
    panels = page.eval("window.lensview.panels")
    type_field(page, "r1", a.panel_bad)
    # The error line, then the panel the worker sends after it (the field
    # shows the document's value again only then).
    page.wait(f"window.lensview.error !== '' && window.lensview.panels > {panels}",
              "an error line and the panel for the refused r1", a.timeout)
    save(out, "panel-error.txt", page.eval("document.getElementById('error').textContent"))
    report["panel_field_after_error"] = page.eval("document.getElementById('field-r1').value")
    page.eval("document.getElementById('view').focus()")
    page.key("KeyZ", "z", 90, modifiers=2)
    page.wait(f"window.lensview.renders >= {renders + 2} && window.lensview.done", "the picture after Ctrl+Z", a.timeout)
    save(out, "undone.rgba", canvas(page))
    report["undone_error"] = page.eval("window.lensview.error")
    page.eval("document.getElementById('redo').click()")
    page.wait(f"window.lensview.renders >= {renders + 3} && window.lensview.done", "the picture after Redo", a.timeout)
    save(out, "redone.rgba", canvas(page))
    # A catalogue glass from the panel's list, as a user picks it.
    page.eval(f"""(() => {{ const s = document.getElementById('field-n.glass');
        s.value = '{a.panel_glass}'; s.dispatchEvent(new Event('change')); }})()""")
    page.wait(f"window.lensview.renders >= {renders + 4} && window.lensview.done", "the picture after the glass", a.timeout)
    save(out, "glass.rgba", canvas(page))
    save(out, "glass.toml", page.eval("window.lensview.sceneToml()"))
    report["overlay"] = page.eval("document.getElementById('overlay').textContent")


OVERLAY_PIXELS = """(() => {
    const c = document.getElementById('optics');
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 3; i < d.length; i += 4) n += d[i] > 0;
    return n;
})()"""
SVGS = "document.querySelectorAll('#analysis-figures svg').length"


def optics(page, a, out, report):
    """F6 and F7 as a user presses them: the overlay canvas gets pixels,
    the analysis panel its SVG figures, and the picture (its canvas and
    the renders count) stays as it was; then the analysis's field set to
    5° adds the spot at 5°. A screenshot of the page into optics.png."""
    before, picture = json.loads(page.eval(STATE)), canvas(page)
    for code, vk in (("F6", 117), ("F7", 118)):
        page.eval("document.getElementById('view').focus()")
        page.key(code, code, vk)
    page.wait(f"window.lensview.optics.segments > 0 && {SVGS} > 0", "the optics overlay and the analysis", a.timeout)
    # Two frames: the canvas drawn and composited.
    page.eval("new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)))")
    state = json.loads(page.eval(STATE))
    report["optics"] = {
        "overlay_pixels": page.eval(OVERLAY_PIXELS),
        "svgs": page.eval(SVGS),
        "labels": state["optics"]["labels"],
        "renders_unchanged": state["renders"] == before["renders"] and state["done"],
        "canvas_unchanged": canvas(page) == picture,
        "analysis": page.eval("document.getElementById('analysis-figures').textContent.slice(0, 300)"),
    }
    shot = page.call("Page.captureScreenshot", format="png", captureBeyondViewport=True)
    save(out, "optics.png", base64.b64decode(shot["data"]))
    page.eval("""(() => { const f = document.getElementById('an-field');
        f.value = '5'; f.dispatchEvent(new Event('input')); })()""")
    page.wait("document.getElementById('analysis-figures').textContent.includes('Spot, field 5')",
              "the spot at 5 degrees", a.timeout)
    report["optics"]["svgs_at_5_deg"] = page.eval(SVGS)
    report["optics"]["renders_unchanged_at_5_deg"] = json.loads(page.eval(STATE))["renders"] == before["renders"]


def downloads(page, a, out, report):
    """Clicks Save scene and Save PNG; keeps the files the browser saved."""
    folder = os.path.join(out, "downloads")
    os.makedirs(folder, exist_ok=True)
    page.call("Browser.setDownloadBehavior", behavior="allow", downloadPath=os.path.abspath(folder))
    for button, ext in (("save-scene", "toml"), ("save-png", "png")):
        page.eval(f"document.getElementById('{button}').click()")
        path = os.path.join(folder, f"cubes.{ext}")
        end = time.monotonic() + a.timeout
        while not os.path.exists(path) and time.monotonic() < end:
            time.sleep(0.05)
        if not os.path.exists(path):
            raise TimeoutError(f"{button}: no download in {folder}: {os.listdir(folder)}")
        shutil.copy(path, os.path.join(out, f"saved.{ext}"))
    report["downloads"] = sorted(os.listdir(folder))


def act_and_wait(page, a, js, renders, what):
    """Runs `js` (a panel button or menu, as a user clicks it); waits for
    the finished picture it starts (the page's `renders`-th)."""
    page.eval(js)
    page.wait(f"window.lensview.renders >= {renders} && window.lensview.done", what, a.timeout)


def panel_adds(page, a, out, report):
    """The Add menu's sphere, its Delete button, then Undo; optionally a
    screenshot of the panel with the sphere's material and the menu."""
    renders = json.loads(page.eval(STATE))["renders"]
    act_and_wait(page, a, """(() => { const s = document.getElementById('add');
        s.value = 'add:sphere'; s.dispatchEvent(new Event('change')); })()""", renders + 1, "the added sphere")
    report["added_selected"] = page.eval("window.lensview.panel.selected")
    save(out, "added.rgba", canvas(page))
    save(out, "added.toml", page.eval("window.lensview.sceneToml()"))
    act_and_wait(page, a, "document.getElementById('action-delete').click()", renders + 2, "the sphere deleted")
    save(out, "deleted.rgba", canvas(page))
    save(out, "deleted.toml", page.eval("window.lensview.sceneToml()"))
    act_and_wait(page, a, "document.getElementById('undo').click()", renders + 3, "the delete undone")
    save(out, "undeleted.rgba", canvas(page))
    if a.screenshot:
        # The sphere selected (its material's rows), the Add menu open as a list.
        page.eval("""(() => { const s = document.getElementById('items');
            s.value = [...s.options].find((o) => o.text.startsWith('sphere')).value;
            s.dispatchEvent(new Event('change')); })()""")
        page.wait("!!document.getElementById('field-shininess')", "the sphere's material", a.timeout)
        page.eval("document.getElementById('add').size = 12")
        shot = page.call("Page.captureScreenshot", format="png")["data"]
        with open(a.screenshot, "wb") as f:
            f.write(base64.b64decode(shot))


def bad_files(page, a, out):
    """The bad scene file through the file input (Chromium: Firefox's BiDi
    has no file-input command), then dropped on the page; then the good one
    (--good) dropped."""
    if a.browser == "chromium":
        doc = page.call("DOM.getDocument")
        node = page.call("DOM.querySelector", nodeId=doc["root"]["nodeId"], selector="#file")["nodeId"]
        page.call("DOM.setFileInputFiles", nodeId=node, files=[os.path.abspath(a.bad)])
        page.wait("window.lensview.error !== ''", "an error line for the bad file", a.timeout)
        save(out, "error.txt", page.eval("document.getElementById('error').textContent"))
        page.eval("window.lensview.error = ''; document.getElementById('error').textContent = ''")
    drop(page, a.bad)
    page.wait("window.lensview.error !== ''", "an error line for the dropped file", a.timeout)
    save(out, "dropped.txt", page.eval("document.getElementById('error').textContent"))
    if a.good:
        # A good one dropped: it replaces the scene and clears the error.
        renders = json.loads(page.eval(STATE))["renders"]
        drop(page, a.good)
        page.wait(f"window.lensview.renders >= {renders + 1} && window.lensview.done && window.lensview.error === ''",
                  "the picture of the dropped good file", a.timeout)
        save(out, "good.rgba", canvas(page))


def drop(page, path):
    """Drops the file at `path` on the page: a drop event carrying it, as
    the browser sends one."""
    with open(path) as f:
        text = json.dumps(f.read())
    name = json.dumps(os.path.basename(path))
    page.eval(f"""(() => {{
        const dt = new DataTransfer();
        dt.items.add(new File([{text}], {name}));
        document.body.dispatchEvent(new DragEvent('drop', {{ dataTransfer: dt, bubbles: true, cancelable: true }}));
    }})()""")


def run(page, url, a, out, report):
    report["first"], report["first_wall_s"] = open_page(page, url, a)
    report["note"] = page.eval("document.getElementById('note').textContent")
    save(out, "first.rgba", canvas(page))
    if a.measure and a.optics:
        optics(page, a, out, report)
    if not a.measure:
        report["moved"] = press(page, a, "KeyW", "w", 87, 2, "the picture after W")
        save(out, "moved.rgba", canvas(page))
        save(out, "moved.toml", page.eval("window.lensview.sceneToml()"))
        report["lens"] = press(page, a, "Digit2", "2", 50, 3, "the picture after the lens key 2")
        save(out, "lens.rgba", canvas(page))
        save(out, "lens.toml", page.eval("window.lensview.sceneToml()"))
        # Mouse-look: what pointer-locked movement sends (headless browsers
        # give no pointer lock).
        renders = json.loads(page.eval(STATE))["renders"]
        page.eval("window.lensview.lookBy(40, -10)")
        page.wait(f"window.lensview.renders >= {renders + 1} && window.lensview.done", "the picture after mouse-look",
                  a.timeout)
        report["looked"] = json.loads(page.eval(STATE))
        save(out, "looked.rgba", canvas(page))
        save(out, "looked.toml", page.eval("window.lensview.sceneToml()"))
        page.eval("window.lensview.lookBy(-40, 10)")
        page.wait(f"window.lensview.renders >= {renders + 2} && window.lensview.done", "the picture looked back",
                  a.timeout)
        if a.browser == "chromium":
            panel_edits(page, a, out, report)
            optics(page, a, out, report)
            downloads(page, a, out, report)
            panel_adds(page, a, out, report)
            light_key(page, a, out, report)
        if a.bad:
            bad_files(page, a, out)
    for name in filter(None, a.presets.split(",")):
        base = url.split("?")[0]
        report[f"preset-{name}"], _ = open_page(page, f"{base}?scene={name}&{a.preset_query}", a)
        save(out, f"preset-{name}.rgba", canvas(page))
    if a.browser == "chromium" and a.presets:
        # The Presets menu, as a user picks from it: the page opens ?scene= it.
        page.eval("""(() => { const s = document.getElementById('presets');
            s.value = 'focal-spot'; s.dispatchEvent(new Event('change')); })()""")
        page.wait("location.search.includes('scene=focal-spot') && window.lensview && window.lensview.done",
                  "the preset picked from the menu", a.timeout)
        report["menu_options"] = page.eval("document.getElementById('presets').options.length")
        save(out, "menu-focal-spot.rgba", canvas(page))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dist", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--query", required=True, help="the page's URL parameters, e.g. scene=cubes&w=160&h=120&spp=4")
    ap.add_argument("--bad", help="a scene file the page must refuse")
    ap.add_argument("--good", help="a scene file to drop on the page after the bad one")
    ap.add_argument("--measure", action="store_true")
    ap.add_argument("--optics", action="store_true", help="with --measure: F6, F7 and optics.png")
    ap.add_argument("--no-isolation", action="store_true",
                    help="serve without COOP/COEP (one thread); webkit: without JSC_useSharedArrayBuffer too")
    ap.add_argument("--presets", default="", help="presets to open after the first page, comma-separated")
    ap.add_argument("--preset-query", default="w=64&h=48&spp=2&seed=3")
    ap.add_argument("--panel-r1", default="3.5", help="the lens's r1 typed into the panel")
    ap.add_argument("--panel-bad", default="0.1", help="an r1 the panel must refuse")
    ap.add_argument("--panel-glass", default="N-SF5", help="the lens's glass picked in the panel")
    ap.add_argument("--browser", choices=("chromium", "firefox", "webkit"), default="chromium",
                    help="firefox, webkit: the first picture, the keys, dropped files and presets"
                         " (no panel, downloads or file input); webkit needs an X display (xvfb-run)")
    ap.add_argument("--screenshot", help="a PNG of the page with the added sphere's material and the Add menu")
    ap.add_argument("--timeout", type=float, default=240)
    a = ap.parse_args()
    # SIGTERM (a timeout) ends through the `finally` below.
    signal.signal(signal.SIGTERM, lambda *_: sys.exit("error: terminated"))
    os.makedirs(a.out, exist_ok=True)
    httpd = serve.server(a.dist, 0, not a.no_isolation)
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    profile = tempfile.mkdtemp(prefix=f"lensview-{a.browser}-")
    browser = page = None
    report = {"console_errors": [], "browser": a.browser}
    try:
        if a.browser == "firefox":
            browser, ws_url = web_bidi.start_firefox(profile)
            page = web_bidi.BidiPage(ws_url)
        elif a.browser == "webkit":
            browser, base = web_webkit.start_webkit(shared=not a.no_isolation)
            page = web_webkit.WebKitPage(base)
        else:
            browser, port = start_chromium(profile)
            page = Page(page_target(port))
            for domain in ("Runtime", "Log", "Page", "DOM"):
                page.call(f"{domain}.enable")
        url = f"http://127.0.0.1:{httpd.server_address[1]}/?{a.query}"
        report["url"] = url
        try:
            run(page, url, a, a.out, report)
        finally:
            report["console_errors"] = page.errors
            # WebKitGTK gives WebDriver no console: only the page's error line.
            report["console_read"] = a.browser != "webkit"
            report["user_agent"] = page.eval("navigator.userAgent")
            report["hardware_concurrency"] = page.eval("navigator.hardwareConcurrency")
            report["cross_origin_isolated"] = page.eval("window.crossOriginIsolated")
            page.close()
    finally:
        with open(os.path.join(a.out, "report.json"), "w") as f:
            json.dump(report, f, indent=1)
        if browser:
            browser.terminate()
            try:
                browser.wait(10)
            except subprocess.TimeoutExpired:
                browser.kill()
                browser.wait()
        httpd.shutdown()
        httpd.server_close()
        shutil.rmtree(profile, ignore_errors=True)
    # The whole report is report.json; a line here (a pipe's reader may
    # only read it at the end).
    print(json.dumps({k: report.get(k) for k in ("browser", "cross_origin_isolated", "console_errors")}))


if __name__ == "__main__":
    main()
