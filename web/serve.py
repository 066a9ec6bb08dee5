#!/usr/bin/env python3
"""Serves lensview's page (web/dist by default) on 127.0.0.1 only, with the
cross-origin isolation headers (COOP/COEP) that threads in the page
need (--no-isolation leaves them out: the page then runs on one thread).
Usage: serve.py [--port N] [--dir DIR] [--no-isolation]; port 0 picks a
free port.
Prints `serving http://127.0.0.1:PORT/` once it listens."""

import argparse
import functools
import http.server
import os
import sys


class Handler(http.server.SimpleHTTPRequestHandler):
    extensions_map = {
        **http.server.SimpleHTTPRequestHandler.extensions_map,
        ".wasm": "application/wasm",
        ".js": "text/javascript",
    }

    isolate = True

    def end_headers(self):
        if self.isolate:
            self.send_header("Cross-Origin-Opener-Policy", "same-origin")
            self.send_header("Cross-Origin-Embedder-Policy", "require-corp")
            self.send_header("Cross-Origin-Resource-Policy", "same-origin")
        self.send_header("Cache-Control", "no-store")
        super().end_headers()

    def log_message(self, fmt, *args):
        if os.environ.get("LENSVIEW_SERVE_LOG"):
            super().log_message(fmt, *args)


class Plain(Handler):
    isolate = False


def server(folder, port=0, isolate=True):
    """An HTTP server of `folder` on 127.0.0.1:`port` (not yet serving);
    without COOP/COEP when not `isolate`."""
    handler = functools.partial(Handler if isolate else Plain, directory=folder)
    return http.server.ThreadingHTTPServer(("127.0.0.1", port), handler)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--port", type=int, default=8034)
    ap.add_argument("--dir", default=os.path.join(here, "dist"))
    ap.add_argument("--no-isolation", action="store_true", help="no COOP/COEP headers (one thread)")
    a = ap.parse_args()
    if not os.path.isfile(os.path.join(a.dir, "index.html")):
        sys.exit(f"error: {a.dir}/index.html is missing: build the page first (web/build.sh)")
    httpd = server(a.dir, a.port, not a.no_isolation)
    print(f"serving http://127.0.0.1:{httpd.server_address[1]}/ (Ctrl-C stops)", flush=True)
    try:
        httpd.serve_forever()
    except KeyboardInterrupt:
        pass


if __name__ == "__main__":
    main()
