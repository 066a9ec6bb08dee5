#!/usr/bin/env bash
# What caustics add to a frame (issue #29 item 3), two builds side by side:
# OLD and NEW run *at once*, one thread each, pinned one to each core
# (`taskset`, the cores swapped every round), so that both see the same
# noise of a shared machine; each round renders every scene with its
# caustics (the default) and then a copy with `[render] caustics = false`.
# Prints the medians of `perf stat -e task-clock` (CPU seconds, to the
# millisecond) and the cost `on/off - 1` of each build, as one table.
# Needs two cores, `taskset` and `perf`.
# Usage: benches/caustics-paired.sh ROUNDS WIDTHxHEIGHT SPP OLD NEW
# Scenes: the shipped ones whose caustics are on (CAUSTIC_SCENES overrides).
set -euo pipefail
ROUNDS=$1; SIZE=$2; SPP=$3; OLD=$4; NEW=$5
# W, H, SCENES, here, dir and the scenes' copies without caustics.
source "$(dirname "$0")/caustics-setup.sh"
# One build's run: "NAME SCENE on|off SECONDS" appended to $dir/times.
one() {
  local name=$1 bin=$2 core=$3 s=$4 v=$5 f=$here/scenes/$4.toml
  [[ $v == off ]] && f=$dir/$s-off.toml
  RAYON_NUM_THREADS=1 taskset -c "$core" perf stat -e task-clock -x, -o "$dir/$name.stat" \
    "$bin" render "$f" --width "$W" --height "$H" --spp "$SPP" -o "$dir/$name.png" >/dev/null 2>&1
  awk -F, -v t="$name $s $v" '/task-clock/ {print t, $1 / 1000}' "$dir/$name.stat" >>"$dir/times"
}
for r in $(seq 1 "$ROUNDS"); do
  a=$(( r % 2 )); b=$(( 1 - a ))
  for s in $SCENES; do
    for v in on off; do
      one OLD "$OLD" "$a" "$s" "$v" & one NEW "$NEW" "$b" "$s" "$v" & wait
    done
  done
done
python3 - "$dir/times" <<'PY'
import collections, statistics as st, sys
t = collections.defaultdict(list)
for line in open(sys.argv[1]):
    b, s, v, secs = line.split()
    t[(b, s, v)].append(float(secs))
print("| scene | OLD on | OLD off | NEW on | NEW off | OLD cost | NEW cost |")
print("|---|---|---|---|---|---|---|")
for s in dict.fromkeys(k[1] for k in t):
    m = {(b, v): st.median(t[(b, s, v)]) for b in ("OLD", "NEW") for v in ("on", "off")}
    cost = lambda b: f"{100 * (m[(b, 'on')] / m[(b, 'off')] - 1):+.0f} %"
    cells = " | ".join(f"{m[(b, v)]:.3f}" for b in ("OLD", "NEW") for v in ("on", "off"))
    print(f"| {s} | {cells} | {cost('OLD')} | {cost('NEW')} |")
PY
