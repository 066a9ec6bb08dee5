#!/usr/bin/env bash
# Serves the built page (web/dist) on http://127.0.0.1:8034/ only, with the
# COOP/COEP headers. Arguments go to serve.py (--port N, --dir DIR).
exec python3 "$(dirname "$0")/serve.py" "$@"
