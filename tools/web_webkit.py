"""WebKit (Safari's engine: WebKitGTK's MiniBrowser) over W3C WebDriver, for
tools/web_page_test.py (--browser webkit): the same few calls as its
Chromium page (eval, wait, navigate, key), so that the page's run is
written once.

WebKitWebDriver (Debian's webkit2gtk-driver) listens on 127.0.0.1 and starts
MiniBrowser in automation mode; it needs an X display (the caller runs this
under xvfb-run). WebKitGTK gives pages no SharedArrayBuffer unless
JavaScriptCore's `useSharedArrayBuffer` option is on (Safari turns it on for
cross-origin isolated pages): the driver is started with
JSC_useSharedArrayBuffer=1. Classic WebDriver has no console log in
WebKitGTK: the page's own error line is what the caller checks. The caller
stops the driver (`terminate`) on every exit; ending the session closes
MiniBrowser."""

import json
import os
import shutil
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request

from web_page_base import PageBase

MINIBROWSER = "/usr/lib/x86_64-linux-gnu/webkit2gtk-4.1/MiniBrowser"


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_webkit(shared=True):
    """Starts WebKitWebDriver; returns it and its base URL. shared=False
    leaves JSC_useSharedArrayBuffer unset (no SharedArrayBuffer: the page
    loads its one-thread build)."""
    exe = shutil.which("WebKitWebDriver")
    if not exe or not os.path.exists(MINIBROWSER):
        sys.exit("error: WebKit is missing: apt-get install webkit2gtk-driver (.ci/run does)")
    if not os.environ.get("DISPLAY"):
        sys.exit("error: WebKit needs an X display: run under xvfb-run")
    port = free_port()
    env = dict(os.environ, JSC_useSharedArrayBuffer="1") if shared else dict(os.environ)
    proc = subprocess.Popen([exe, f"--port={port}", "--host=127.0.0.1"], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    base = f"http://127.0.0.1:{port}"
    for _ in range(300):
        try:
            with urllib.request.urlopen(base + "/status", timeout=5) as r:
                if json.load(r)["value"].get("ready"):
                    return proc, base
        except (OSError, ValueError, KeyError):
            pass
        if proc.poll() is not None:
            sys.exit(f"error: WebKitWebDriver exited at start (status {proc.returncode})")
        time.sleep(0.1)
    proc.kill()
    sys.exit("error: WebKitWebDriver did not answer in 30 s")


class WebKitPage(PageBase):
    """One WebDriver session: MiniBrowser's one window."""

    def __init__(self, base):
        self.base = base
        self.errors = []
        caps = {"webkitgtk:browserOptions": {"binary": MINIBROWSER, "args": ["--automation"]}}
        self.session = self.req("POST", "/session", {"capabilities": {"alwaysMatch": caps}})["sessionId"]

    def req(self, method, path, body=None):
        data = json.dumps(body).encode() if body is not None else None
        r = urllib.request.Request(self.base + path, data=data, method=method,
                                   headers={"Content-Type": "application/json"})
        try:
            with urllib.request.urlopen(r, timeout=300) as f:
                return json.load(f)["value"]
        except urllib.error.HTTPError as e:
            raise RuntimeError(f"{method} {path}: {e.read().decode(errors='replace')[:500]}") from None

    def call(self, method, path, body=None):
        return self.req(method, f"/session/{self.session}{path}", body)

    def eval(self, expr):
        """`expr`'s value (as JSON crosses), its promise awaited."""
        script = (f"const done = arguments[arguments.length - 1];"
                  f"Promise.resolve().then(() => ({expr})).then("
                  f"v => done(JSON.stringify({{v}})), e => done(JSON.stringify({{e: String(e)}})));")
        r = json.loads(self.call("POST", "/execute/async", {"script": script, "args": []}))
        if "e" in r:
            raise RuntimeError(f"{expr}: {r['e']}")
        return r.get("v")

    def navigate(self, url):
        self.call("POST", "/url", {"url": url})

    def key(self, code, key, vk, modifiers=0):
        """One key pressed and released as a user types it (`key`: the
        character; WebKit derives `code` from it)."""
        del code, vk, modifiers
        actions = [{"type": "keyDown", "value": key}, {"type": "keyUp", "value": key}]
        self.call("POST", "/actions", {"actions": [{"type": "key", "id": "keyboard", "actions": actions}]})
        self.call("DELETE", "/actions")

    def close(self):
        try:
            self.call("DELETE", "")
        except (RuntimeError, OSError):
            pass
