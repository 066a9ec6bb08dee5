# Sourced by the window benches (viewer-cost.sh, viewer-flight.sh,
# viewer-caustics.sh; not run alone) with their default X display number:
# a temporary folder `tmp`, an Xvfb server on :DISPLAY_NUM (default the
# argument) as DISPLAY, and `app`, the viewer's pid while one runs; on
# exit the viewer, the server and the folder are removed.
tmp=$(mktemp -d)
display=:${DISPLAY_NUM:-$1}
Xvfb "$display" -screen 0 1920x1200x24 -nolisten tcp -noreset >/dev/null 2>&1 &
xvfb=$!
app=""
trap '[ -n "$app" ] && kill $app 2>/dev/null; kill $xvfb 2>/dev/null || true; rm -rf "$tmp"' EXIT
export DISPLAY=$display XDG_RUNTIME_DIR=$tmp
for _ in $(seq 100); do [ -e "/tmp/.X11-unix/X${display#:}" ] && break; sleep 0.1; done
