"""What the browsers' page classes of tools/web_page_test.py share: waiting
for the page's state (the Chromium, Firefox and WebKit classes each give
`eval`), and for the two driven over a websocket (the DevTools protocol,
WebDriver BiDi) the command loop."""

import json
import time


class PageBase:
    def wait(self, expr, what, timeout):
        """Polls `expr` until it is true; an evaluation that fails while
        the page loads (again: it may reload itself) counts as not yet."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            try:
                if self.eval(expr):
                    return
            except RuntimeError:
                pass
            time.sleep(0.05)
        try:
            state = self.eval("JSON.stringify(window.lensview)")
        except RuntimeError as e:
            state = f"unreadable ({e})"
        raise TimeoutError(f"the page did not get {what} in {timeout} s; state: {state}")


class SocketPage(PageBase):
    """A page driven by JSON commands over the websocket `ws`: a command's
    reply is the message with its id, every other message an event
    (`event`); `failure` says why a reply is an error (None if it is not)."""

    def __init__(self, ws):
        self.ws = ws
        self.next_id = 0
        self.errors = []

    def call(self, method, **params):
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv())
            if msg.get("id") == self.next_id:
                failed = self.failure(msg)
                if failed is not None:
                    raise RuntimeError(f"{method}: {failed}")
                return msg.get("result", {})
            self.event(msg)
