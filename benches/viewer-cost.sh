#!/usr/bin/env bash
# What the open window costs the tracer, in one run under Xvfb (Mesa
# lavapipe), for one or two builds in alternating rounds:
#  - throughput: the median `render_ms` of the "1 spp" stages the render
#    thread finished after the first generation (the frame log's `stages`,
#    drawn or not) against the median of `bench --frame-only` (3 runs)
#    taken headless after each key, while the window sits idle with its
#    picture refined: the two interleaved within seconds, because this
#    machine's speed drifts by a quarter over minutes. The keys alternate
#    W and S (a step forward, a step back), so every frame shows about
#    the view `bench` renders (the window opens at the scene's camera).
#  - latency: for the first frame of each generation after a key, the
#    time from the input to the screen (`ms_since_input`) against what it
#    cannot beat: the input to the frame leaving the render thread
#    (`sent_ms_since_input`) plus one present (`present_ms`);
#  - presents per second and the CPU seconds of the window's main thread
#    and of the rasterizer's threads (llvmpipe) per second of wall time
#    (the time the headless frames took left out).
# Needs xvfb, xdotool and python3. From the repository root:
#   bash benches/viewer-cost.sh BINARY [BINARY2] [ROUNDS] [WIDTHxHEIGHT] [SCENE] [KEYS]
# DISPLAY_NUM picks the X display (default 77); KEYS per round (default 8).
set -euo pipefail
A=$1; B=${2:-}; rounds=${3:-3}; size=${4:-1280x720}; scene=${5:-scenes/cubes.toml}; keys=${6:-8}
w=${size%x*}; h=${size#*x}
lscpu | grep 'Model name' || true
# tmp, an Xvfb server as DISPLAY, app; all removed on exit.
source "$(dirname "$0")/xvfb-setup.sh" 77

# Like with like: `bench --frame-only` traces no photons and gathers none,
# so the window and the headless frames both get the scene with its
# caustics off (what caustics cost is benches/caustics-cost.sh's to say;
# with them on, the window's stages carried photon passes and gathers the
# headless frames did not, and read as half of headless speed).
plain=$tmp/scene.toml
python3 "$(dirname "$0")/caustics-off.py" "$scene" "$plain"
echo "scene: $scene, with caustics off in the window and headless alike"

# cpu TAG: CPU seconds of the viewer's threads, summed by kind.
cpu() {
    for t in /proc/$app/task/*; do
        read -r name < "$t/comm"
        # utime and stime, fields 14 and 15 of stat (after the comm).
        ticks=$(sed 's/.*) //' "$t/stat" | awk '{print $12 + $13}')
        [ "${t##*/}" = "$app" ] && name=main
        echo "$1 $name $ticks"
    done
}

one() { # BIN TAG ROUND
    local bin=$1 tag=$2 r=$3
    local log=$tmp/frames-$tag-$r.jsonl
    "$bin" view "$plain" --width "$w" --height "$h" --max-spp 8 --no-panel \
        --frame-log "$log" --exit-after $((keys * 5 + 30)) >/dev/null 2>&1 &
    app=$!
    local win=""
    for _ in $(seq 300); do win=$(xdotool search --name '^lensview' 2>/dev/null | head -1 || true); [ -n "$win" ] && break; sleep 0.1; done
    [ -n "$win" ] || { echo "the window did not appear"; exit 1; }
    xdotool windowfocus --sync "$win"
    sleep 3
    cpu start > "$tmp/cpu-$tag-$r"
    local t0 b0 away=0 key=w
    t0=$(date +%s.%N)
    for _ in $(seq "$keys"); do
        xdotool key --window "$win" "$key"
        if [ "$key" = w ]; then key=s; else key=w; fi
        sleep 2.5
        b0=$(date +%s.%N)
        "$bin" bench --frame-only --width "$w" --height "$h" --runs 3 "$plain" 2>&1 |
            awk -v t="$tag" -v r="$r" -v s="${w}x${h}" '$1=="frame" && $2==s {print r, t, $11}' >> "$tmp/headless"
        away=$(echo "$away + $(date +%s.%N) - $b0" | bc)
    done
    cpu end >> "$tmp/cpu-$tag-$r"
    echo "$(date +%s.%N) - $t0" | bc > "$tmp/wall-$tag-$r"
    echo "$away" > "$tmp/away-$tag-$r"
    kill "$app" 2>/dev/null || true
    wait "$app" 2>/dev/null || true
    app=""
}

for r in $(seq 1 "$rounds"); do
    if [ -z "$B" ]; then one "$A" A "$r"
    elif (( r % 2 )); then one "$A" A "$r"; one "$B" B "$r"
    else one "$B" B "$r"; one "$A" A "$r"; fi
done

python3 - "$tmp" "$A" "$B" <<'PY'
import json, statistics as st, sys, glob, os
tmp, names = sys.argv[1], {"A": sys.argv[2], "B": sys.argv[3]}
head = {}
for line in open(f"{tmp}/headless"):
    r, t, ms = line.split()
    head.setdefault(t, {}).setdefault(r, []).append(float(ms))
med = lambda v: st.median(v) if v else float("nan")
for tag in ("A", "B"):
    logs = sorted(glob.glob(f"{tmp}/frames-{tag}-*.jsonl"))
    if not logs:
        continue
    one, lat, floor, presents, active, rounds = [], [], [], 0, 0.0, []
    main_cpu = llvm_cpu = tracer_cpu = other_cpu = 0.0
    for log in logs:
        r = log.rsplit("-", 1)[1].split(".")[0]
        frames = [json.loads(l) for l in open(log)]
        # Every "1 spp" stage the render thread finished after the first
        # generation (the log's `stages`), drawn or not.
        first_gen = frames[0]["generation"] if frames else 0
        stages = [s for f in frames for s in f.get("stages", []) if s["generation"] != first_gen]
        mine = [s["render_ms"] for s in stages if s["level"] == "1 spp"]
        one += mine
        rounds.append(100 * med(head.get(tag, {}).get(r, [])) / med(mine))
        gens = sorted({f["generation"] for f in frames})[1:]
        for g in gens:
            f = next(f for f in frames if f["generation"] == g)
            lat.append(f["ms_since_input"])
            floor.append(f["sent_ms_since_input"] + f["present_ms"])
        w = float(open(f"{tmp}/wall-{tag}-{r}").read())
        active += w - float(open(f"{tmp}/away-{tag}-{r}").read())
        ts = [f["t"] for f in frames]
        t_end = max(ts) if ts else 0
        presents += sum(1 for t in ts if t >= t_end - w)
        cpu = {}
        for line in open(f"{tmp}/cpu-{tag}-{r}"):
            when, name, ticks = line.split()
            cpu.setdefault(name, {}).setdefault(when, 0)
            cpu[name][when] += int(ticks)
        hz = os.sysconf("SC_CLK_TCK")
        for name, v in cpu.items():
            d = (v.get("end", 0) - v.get("start", 0)) / hz
            if name == "main":
                main_cpu += d
            elif name.startswith("llvmpipe"):
                llvm_cpu += d
            elif name.startswith("lensview-render"):
                tracer_cpu += d
            else:
                other_cpu += d
    h = med([x for v in head.get(tag, {}).values() for x in v])
    print(f"{tag} = {names[tag]}")
    print(f"  1-spp frame: headless median {h:.1f} ms; in the window median {med(one):.1f} ms over {len(one)} frames"
          f" -> throughput {100 * h / med(one):.0f} % of headless (rounds: {', '.join(f'{x:.0f}' for x in rounds)} %)")
    excess = [l - f for l, f in zip(lat, floor)]
    print(f"  first frame after a key on screen: median {med(lat):.1f} ms after the input;"
          f" frame sent + one present: median {med(floor):.1f} ms; excess median {med(excess):.1f} ms, max {max(excess):.1f} ms ({len(lat)} keys)")
    print(f"  presents {presents / active:.1f}/s; CPU s per wall s: window main thread {main_cpu / active:.2f},"
          f" rasterizer (llvmpipe) {llvm_cpu / active:.2f}, tracer {tracer_cpu / active:.2f}, other threads {other_cpu / active:.2f}")
PY
