#!/usr/bin/env bash
# Issue #31's frame-time table: the five shipped scenes with two builds
# side by side (benches/alternate-frames.sh per scene: alternating rounds,
# median ratio NEW/OLD), then the lens systems' 1-spp frames with NEW alone,
# round-robin in one run: the N-BK7 singlet, the AC254-100-A achromat of the
# same focal length and the double Gauss (benches/systems/).
# Usage: benches/systems-frames.sh OLD_BINARY NEW_BINARY [ROUNDS] [RUNS]
set -euo pipefail
A=$1; B=$2; ROUNDS=${3:-4}; RUNS=${4:-5}
lscpu | grep 'Model name' || true
for s in cubes primitives optical-bench rim-lens focal-spot; do
  echo "== scenes/$s.toml"
  bash benches/alternate-frames.sh "$A" "$B" "$ROUNDS" "$RUNS" "scenes/$s.toml" | grep -v 'Model name'
done
for r in $(seq 1 "$ROUNDS"); do
  for s in singlet achromat double-gauss; do
    "$B" bench --frame-only --runs "$RUNS" "benches/systems/$s.toml" 2>&1 | awk -v s="$s" '/^frame/ {print s, $2, $8, $11}'
  done
done | python3 -c '
import sys, statistics as st
rows = {}
for line in sys.stdin:
    s, size, fastest, median = line.split()
    rows.setdefault((s, size), []).append(float(fastest))
for (s, size), v in sorted(rows.items()):
    print(f"{s} {size}: fastest {min(v):.2f} ms, median of rounds {st.median(v):.2f} ms ({len(v)} rounds)")
'
