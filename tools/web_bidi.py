"""Headless Firefox over WebDriver BiDi, for tools/web_page_test.py
(--browser firefox): the same few calls as its Chromium page (eval, wait,
canvas, navigate, key), so that the page's run is written once.

Firefox (Debian's firefox-esr) starts with a new profile and
`--remote-debugging-port 0`; it listens on 127.0.0.1 only and writes the
port it took to the profile's WebDriverBiDiServer.json. The caller stops it
(`terminate`) on every exit."""

import json
import os
import shutil
import subprocess
import sys
import time

import websocket  # websocket-client, from PyPI

from web_page_base import SocketPage

# Prefs for a quiet test profile: nothing fetched from the network, no
# first-run pages (the remote agent's recommended prefs add the rest).
PREFS = {
    "browser.shell.checkDefaultBrowser": False,
    "browser.startup.homepage_override.mstone": "ignore",
    "datareporting.policy.dataSubmissionEnabled": False,
    "toolkit.telemetry.reportingpolicy.firstRun": False,
    "app.update.disabledForTesting": True,
    "network.captive-portal-service.enabled": False,
    "network.connectivity-service.enabled": False,
    "browser.download.dir": "",
}


def start_firefox(profile):
    """Starts headless Firefox on `profile`; returns it and its BiDi URL."""
    exe = shutil.which("firefox-esr") or shutil.which("firefox")
    if not exe:
        sys.exit("error: firefox is missing: apt-get install firefox-esr (.ci/run does)")
    with open(os.path.join(profile, "user.js"), "w") as f:
        for k, v in PREFS.items():
            f.write(f"user_pref({json.dumps(k)}, {json.dumps(v)});\n")
    proc = subprocess.Popen([exe, "--headless", "--no-remote", "--profile", profile,
                             "--remote-debugging-port", "0", "about:blank"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    port_file = os.path.join(profile, "WebDriverBiDiServer.json")
    for _ in range(600):
        if os.path.exists(port_file):
            try:
                with open(port_file) as f:
                    port = json.load(f)["ws_port"]
                return proc, f"ws://127.0.0.1:{port}/session"
            except (ValueError, KeyError):
                pass  # being written
        if proc.poll() is not None:
            sys.exit(f"error: firefox exited at start (status {proc.returncode})")
        time.sleep(0.1)
    proc.kill()
    sys.exit("error: firefox did not open its WebDriver BiDi port in 60 s")


class BidiPage(SocketPage):
    """One BiDi session on Firefox's first tab: commands, and the console
    errors and uncaught exceptions seen (log.entryAdded of level error)."""

    def __init__(self, ws_url):
        ws = None
        for _ in range(100):
            try:
                ws = websocket.create_connection(ws_url, timeout=60, suppress_origin=True)
                break
            except OSError:
                time.sleep(0.1)
        if ws is None:
            raise RuntimeError(f"cannot connect to {ws_url}")
        super().__init__(ws)
        self.call("session.new", capabilities={"alwaysMatch": {"acceptInsecureCerts": True}})
        self.context = self.call("browsingContext.getTree")["contexts"][0]["context"]
        self.call("session.subscribe", events=["log.entryAdded"])

    @staticmethod
    def failure(msg):
        return f"{msg.get('error')}: {msg.get('message')}" if msg.get("type") == "error" else None

    def event(self, msg):
        if msg.get("method") == "log.entryAdded":
            p = msg.get("params", {})
            if p.get("level") == "error":
                self.errors.append(f"{p.get('type', 'console')}.error: {p.get('text', '')}")

    def eval(self, expr):
        """`expr`'s value (as JSON crosses: strings, numbers, booleans,
        null)."""
        wrapped = f"(async () => JSON.stringify(await ({expr})))()"
        r = self.call("script.evaluate", expression=wrapped, target={"context": self.context},
                      awaitPromise=True, resultOwnership="none")
        if r.get("type") == "exception":
            raise RuntimeError(f"{expr}: {r.get('exceptionDetails', {}).get('text')}")
        v = r.get("result", {})
        return json.loads(v["value"]) if v.get("type") == "string" else None

    def navigate(self, url):
        self.call("browsingContext.navigate", context=self.context, url=url, wait="complete")

    def key(self, code, key, vk, modifiers=0):
        """One key pressed and released as a user types it (`key`: the
        character; Firefox derives `code` from it on its US layout)."""
        del code, vk, modifiers
        actions = [{"type": "keyDown", "value": key}, {"type": "keyUp", "value": key}]
        self.call("input.performActions", context=self.context,
                  actions=[{"type": "key", "id": "keyboard", "actions": actions}])
        self.call("input.releaseActions", context=self.context)

    def close(self):
        try:
            self.call("session.end")
        except (RuntimeError, OSError, websocket.WebSocketException):
            pass
