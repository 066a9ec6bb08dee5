#!/usr/bin/env bash
# What caustics add to a frame (issue #29 item 3): `render` of each scene
# with its caustics (the default) and of a copy with `[render] caustics =
# false`, for one or more builds, ROUNDS rounds, the builds' order
# alternating; prints the medians of wall and CPU (user + system) seconds
# and the cost `on/off - 1` from each.
# Usage: benches/caustics-cost.sh ROUNDS WIDTHxHEIGHT SPP BINARY [BINARY...]
# Scenes: the shipped ones whose caustics are on (CAUSTIC_SCENES overrides).
set -euo pipefail
ROUNDS=$1; SIZE=$2; SPP=$3; shift 3
# W, H, SCENES, here, dir and the scenes' copies without caustics.
source "$(dirname "$0")/caustics-setup.sh"
bins=("$@")
for r in $(seq 1 "$ROUNDS"); do
  if (( r % 2 )); then order=("${bins[@]}"); else order=(); for ((i=${#bins[@]}-1; i>=0; i--)); do order+=("${bins[$i]}"); done; fi
  for b in "${order[@]}"; do
    for s in $SCENES; do
      for v in on off; do
        f=$here/scenes/$s.toml; [[ $v == off ]] && f=$dir/$s-off.toml
        /usr/bin/time -f "$b $s $v %e %U %S" "$b" render "$f" --width "$W" --height "$H" --spp "$SPP" -o "$dir/out.png" 2>>"$dir/times" >/dev/null
      done
    done
  done
done
python3 - "$dir/times" <<'PY'
import collections, statistics as st, sys
wall, cpu = collections.defaultdict(list), collections.defaultdict(list)
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) != 6 or f[2] not in ('on', 'off'):
        continue
    b, s, v = f[:3]
    wall[(b, s, v)].append(float(f[3])); cpu[(b, s, v)].append(float(f[4]) + float(f[5]))
for b in dict.fromkeys(k[0] for k in wall):
    print(f"{b}:")
    print("| scene | on (s) | off (s) | cost, wall | cost, CPU |")
    print("|---|---|---|---|---|")
    for s in dict.fromkeys(k[1] for k in wall if k[0] == b):
        on, off = st.median(wall[(b, s, 'on')]), st.median(wall[(b, s, 'off')])
        con, coff = st.median(cpu[(b, s, 'on')]), st.median(cpu[(b, s, 'off')])
        cost = lambda a, b: f"{100 * (a / b - 1):+.0f} %" if b > 0 else "n/a (under `time`'s 10 ms)"
        print(f"| {s} | {on:.3f} | {off:.3f} | {cost(on, off)} | {cost(con, coff)} |")
PY
