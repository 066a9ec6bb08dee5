#!/usr/bin/env bash
# Measures the viewer's latency from its own frame log, in a real window under
# Xvfb (Mesa lavapipe): after each camera move (a W key press), how long until
# the first refined frame and the first full-resolution 1-spp frame reach the
# screen, and what presenting a frame costs the viewer (copy + overlay +
# present). Needs xvfb, xdotool and python3; run from the repository root:
#   bash benches/viewer-latency.sh [SCENE] [WIDTHxHEIGHT]
set -euo pipefail
scene=${1:-scenes/cubes.toml}
size=${2:-1280x720}
w=${size%x*}; h=${size#*x}
cargo build --release --quiet
tmp=$(mktemp -d)
display=:$((200 + RANDOM % 300))
Xvfb "$display" -screen 0 1920x1200x24 -nolisten tcp -noreset >/dev/null 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null || true; cp "$tmp/frames.jsonl" /tmp/last-frames.jsonl 2>/dev/null || true; rm -rf "$tmp"' EXIT
export DISPLAY=$display XDG_RUNTIME_DIR=$tmp
for _ in $(seq 100); do [ -e "/tmp/.X11-unix/X${display#:}" ] && break; sleep 0.1; done
./target/release/lensview view "$scene" --width "$w" --height "$h" --max-spp 4 \
    --no-panel --frame-log "$tmp/frames.jsonl" --exit-after 60 >/dev/null 2>&1 &
app=$!
win=""
for _ in $(seq 300); do win=$(xdotool search --name '^lensview' 2>/dev/null | head -1 || true); [ -n "$win" ] && break; sleep 0.1; done
[ -n "$win" ] || { echo "the window did not appear"; exit 1; }
xdotool windowfocus --sync "$win"
sleep 4
for _ in $(seq 8); do
    xdotool key --window "$win" w
    sleep 2
done
# Escape twice: with nothing unsaved, one press only asks for a second.
xdotool key --window "$win" Escape
sleep 0.5
xdotool key --window "$win" Escape
wait $app || true
python3 - "$tmp/frames.jsonl" <<'PY'
import json, statistics, sys
frames = [json.loads(l) for l in open(sys.argv[1])]
gens = sorted({f["generation"] for f in frames})[1:]  # skip the window's first generation
first, full, present = [], [], [f["present_ms"] for f in frames]
for g in gens:
    fs = [f for f in frames if f["generation"] == g]
    first.append(fs[0]["ms_since_input"])
    one = [f["ms_since_input"] for f in fs if f["spp"] >= 1]
    if one:
        full.append(one[0])
med = lambda v: statistics.median(v) if v else float("nan")
print(f"camera moves measured: {len(gens)}")
print(f"first refined frame on screen after input: median {med(first):.1f} ms, max {max(first):.1f} ms  (level: {frames[-1]['width']}x{frames[-1]['height']})")
print(f"first full-resolution 1-spp frame:        median {med(full):.1f} ms")
print(f"viewer present cost (copy+overlay+present): median {med(present):.2f} ms over {len(present)} frames")
print("first levels drawn:", sorted({f['level'] for g in gens for f in frames if f['generation']==g and f['ms_since_input']==min(x['ms_since_input'] for x in frames if x['generation']==g)}))
PY
