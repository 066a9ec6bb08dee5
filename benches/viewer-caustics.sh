#!/usr/bin/env bash
# What caustics cost the window (issue #29 item 3): the time the render
# thread takes to refine a scene's first picture to --max-spp, with its
# caustics (the default) and without (`[render] caustics = false`,
# benches/caustics-off.py), for one or two builds in alternating rounds,
# under Xvfb (Mesa lavapipe). Time = the sum of the `render_ms` of every
# stage of the first generation (the frame log's `stages`, drawn or not:
# photon passes, samples and gathers), so the window's own presents are
# left out. Prints each round and the medians.
# Needs xvfb, xdotool and python3. From the repository root:
#   bash benches/viewer-caustics.sh SCENE BINARY [BINARY2] [ROUNDS] [WIDTHxHEIGHT] [MAX_SPP]
# DISPLAY_NUM picks the X display (default 78).
set -euo pipefail
scene=$1; A=$2; B=${3:-}; rounds=${4:-3}; size=${5:-1280x720}; spp=${6:-64}
w=${size%x*}; h=${size#*x}
lscpu | grep 'Model name' || true
grep -q avx512f /proc/cpuinfo && echo "avx512f: yes" || echo "avx512f: no"
# tmp, an Xvfb server as DISPLAY, app; all removed on exit.
source "$(dirname "$0")/xvfb-setup.sh" 78
python3 "$(dirname "$0")/caustics-off.py" "$scene" "$tmp/off.toml"

one() { # BIN TAG ROUND on|off
    local bin=$1 tag=$2 r=$3 v=$4 file=$scene
    [[ $v == off ]] && file=$tmp/off.toml
    local log=$tmp/frames-$tag-$v-$r.jsonl
    "$bin" view "$file" --width "$w" --height "$h" --max-spp "$spp" --no-panel \
        --frame-log "$log" --exit-after 120 >/dev/null 2>&1 &
    app=$!
    # Until the last stage is shown (or the window gives up).
    for _ in $(seq 1200); do
        grep -q "\"spp\":$spp[,}]" "$log" 2>/dev/null && break
        kill -0 "$app" 2>/dev/null || break
        sleep 0.1
    done
    kill "$app" 2>/dev/null || true
    wait "$app" 2>/dev/null || true
    app=""
}

for r in $(seq 1 "$rounds"); do
    for v in on off; do
        if [ -z "$B" ]; then one "$A" A "$r" "$v"
        elif (( r % 2 )); then one "$A" A "$r" "$v"; one "$B" B "$r" "$v"
        else one "$B" B "$r" "$v"; one "$A" A "$r" "$v"; fi
    done
done

python3 - "$tmp" "$A" "$B" "$spp" <<'PY'
import glob, json, statistics as st, sys
tmp, names, spp = sys.argv[1], {"A": sys.argv[2], "B": sys.argv[3]}, int(sys.argv[4])
for tag in ("A", "B"):
    if not names[tag]:
        continue
    res = {}
    for v in ("on", "off"):
        for log in sorted(glob.glob(f"{tmp}/frames-{tag}-{v}-*.jsonl")):
            frames = [json.loads(l) for l in open(log)]
            if not frames or not any(f["spp"] == spp for f in frames):
                print(f"{tag} {v} {log}: never reached {spp} spp")
                continue
            g = frames[0]["generation"]
            ms = sum(s["render_ms"] for f in frames for s in f.get("stages", []) if s["generation"] == g)
            res.setdefault(v, []).append(ms)
    on, off = res.get("on", []), res.get("off", [])
    print(f"{tag} ({names[tag]}): to {spp} spp, ms per round with caustics {[round(x) for x in on]}, without {[round(x) for x in off]}")
    if on and off:
        print(f"   median {st.median(on):.0f} ms with, {st.median(off):.0f} ms without: caustics +{100 * (st.median(on) / st.median(off) - 1):.0f} %")
PY
