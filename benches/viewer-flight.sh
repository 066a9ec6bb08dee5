#!/usr/bin/env bash
# The flight as a user sees it, under Xvfb (Mesa lavapipe): a flight key
# held for SECONDS (W, then S, in turn), ROUNDS times, for one or two
# builds in alternating rounds. Per build: the pictures of the flight
# shown per second of hold (presents of distinct generations between
# key-down and key-up, from the frame log), the stages they showed, their
# median render time, and the time from key-up to the last pose refined to
# the sample cap. Needs xvfb, xdotool and python3. From the repository root:
#   bash benches/viewer-flight.sh BINARY [BINARY2] [ROUNDS] [WIDTHxHEIGHT] [SCENE] [SECONDS]
# DISPLAY_NUM picks the X display (default 78).
set -euo pipefail
A=$1; B=${2:-}; rounds=${3:-3}; size=${4:-1280x720}; scene=${5:-scenes/cubes.toml}; hold=${6:-2}
w=${size%x*}; h=${size#*x}
lscpu | grep 'Model name' || true
grep -o -m1 'avx512f' /proc/cpuinfo || echo "no avx512f"
# tmp, an Xvfb server as DISPLAY, app; all removed on exit.
source "$(dirname "$0")/xvfb-setup.sh" 78

one() { # BIN TAG ROUND
    local bin=$1 tag=$2 r=$3
    local log=$tmp/frames-$tag-$r.jsonl
    "$bin" view "$scene" --width "$w" --height "$h" --max-spp 4 --no-panel \
        --frame-log "$log" --exit-after 120 >/dev/null 2>&1 &
    app=$!
    local win=""
    for _ in $(seq 300); do win=$(xdotool search --name '^lensview' 2>/dev/null | head -1 || true); [ -n "$win" ] && break; sleep 0.1; done
    [ -n "$win" ] || { echo "the window did not appear"; exit 1; }
    xdotool windowfocus --sync "$win"
    sleep 3
    for key in w s; do
        local n0; n0=$(wc -l < "$log")
        xdotool keydown --window "$win" "$key"; sleep "$hold"; xdotool keyup --window "$win" "$key"
        local n1; n1=$(wc -l < "$log")
        sleep 3
        echo "$tag $r $n0 $n1 $log" >> "$tmp/holds"
    done
    kill "$app" 2>/dev/null || true
    wait "$app" 2>/dev/null || true
    app=""
}

for r in $(seq 1 "$rounds"); do
    if [ -z "$B" ]; then one "$A" A "$r"
    elif (( r % 2 )); then one "$A" A "$r"; one "$B" B "$r"
    else one "$B" B "$r"; one "$A" A "$r"; fi
done

python3 - "$tmp/holds" "$hold" "$A" "${B:-}" <<'PY'
import json, statistics as st, sys, collections
holds, hold, names = sys.argv[1], float(sys.argv[2]), {"A": sys.argv[3], "B": sys.argv[4]}
per = collections.defaultdict(lambda: {"fps": [], "render": [], "levels": collections.Counter(), "settle": []})
for line in open(holds):
    tag, r, n0, n1, log = line.split()
    frames = [json.loads(l) for l in open(log)]
    g0 = max([f["generation"] for f in frames[:int(n0)]] or [0])
    during = [f for f in frames[int(n0):int(n1)] if f["generation"] > g0]
    gens = {f["generation"] for f in during}
    d = per[tag]
    d["fps"].append(len(gens) / hold)
    d["render"] += [f["render_ms"] for f in during]
    d["levels"].update(f["level"] for f in during)
    after = frames[int(n1):]
    if during and after:
        t_up = during[-1]["t"]
        done = [f for f in after if f["spp"] >= 4]
        if done:
            d["settle"].append((done[0]["t"] - t_up) * 1e3)
for tag, d in sorted(per.items()):
    print(f"{tag} {names[tag]}: flight pictures/s per hold {[round(x, 1) for x in d['fps']]}, median {st.median(d['fps']):.1f}; "
          f"render median {st.median(d['render'] or [0]):.1f} ms; levels {dict(d['levels'])}; "
          f"last present of the hold to 4 spp: median {st.median(d['settle'] or [0]):.0f} ms")
PY
