"""What every browser's page class of tools/web_page_test.py shares: waiting
for the page's state (the Chromium, Firefox and WebKit classes each give
`eval`)."""

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
