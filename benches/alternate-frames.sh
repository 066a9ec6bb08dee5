#!/usr/bin/env bash
# Times two builds side by side: ROUNDS rounds of `bench --frame-only`,
# alternating which build goes first, then the median of the per-round
# ratios B/A for the fastest and the median frame at 400x400 and 1280x720.
# Usage: benches/alternate-frames.sh OLD_BINARY NEW_BINARY [ROUNDS] [RUNS] [SCENE]
# (SCENE: the cubes scene when absent.)
set -euo pipefail
A=$1; B=$2; ROUNDS=${3:-10}; RUNS=${4:-30}; SCENE=${5:-}
lscpu | grep 'Model name' || true
log=$(mktemp)
trap 'rm -f "$log"' EXIT
for r in $(seq 1 "$ROUNDS"); do
  if (( r % 2 )); then order=("$A" "$B"); else order=("$B" "$A"); fi
  for bin in "${order[@]}"; do
    tag=A; [[ $bin == "$B" ]] && tag=B
    "$bin" bench --frame-only --runs "$RUNS" $SCENE 2>&1 | awk -v r="$r" -v t="$tag" '/^frame/ {print r, t, $2, $8, $11}' >> "$log"
  done
done
python3 - "$log" <<'PY'
import sys, statistics as st
rows = {}
for line in open(sys.argv[1]):
    r, tag, size, fastest, median = line.split()
    rows.setdefault((size, r), {})[tag] = (float(fastest), float(median))
for size in sorted({s for s, _ in rows}):
    pairs = [v for (s, _), v in rows.items() if s == size and len(v) == 2]
    rf = st.median(p["B"][0] / p["A"][0] for p in pairs)
    rm = st.median(p["B"][1] / p["A"][1] for p in pairs)
    fa = min(p["A"][0] for p in pairs); fb = min(p["B"][0] for p in pairs)
    print(f"{size}: fastest A {fa:.2f} ms, B {fb:.2f} ms; median ratio B/A of fastest {rf:.3f}, of medians {rm:.3f} ({len(pairs)} rounds)")
PY
