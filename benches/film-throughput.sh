#!/usr/bin/env bash
# Issue #35's speed figures: frames per hour of `lensview film` in one
# process against the same frames on a local Ray cluster of two one-CPU
# worker nodes (tools/ray_film.py), alternating ROUNDS times, in one run.
# Runs in its own network and PID namespaces as tools/ray_film_test.sh does
# (root). Usage: benches/film-throughput.sh LENSVIEW [FRAMES] [SPP] [WxH] [ROUNDS]
set -euo pipefail
if [[ ${LENSVIEW_IN_NS:-} != 1 ]]; then
  exec env LENSVIEW_IN_NS=1 unshare --net --pid --fork --mount-proc bash "$0" "$@"
fi
BIN=$(realpath "$1"); FRAMES=${2:-8}; SPP=${3:-64}; SIZE=${4:-1920x1080}; ROUNDS=${5:-2}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
WORK=$(mktemp -d -p "$ROOT/target" film-throughput.XXXX)
source "$ROOT/tools/ray_cluster.sh"
start_cluster 6381 "$WORK" 2
trap 'ray stop --force >/dev/null 2>&1 || true; rm -rf "$WORK"' EXIT
lscpu | grep 'Model name'
W=${SIZE%x*}; H=${SIZE#*x}
# A flight of exactly FRAMES frames at 2 fps: both runs film all of it.
python3 - "$ROOT/flights/cubes-orbit.toml" "$WORK/flight.toml" "$FRAMES" <<'PY'
import sys, re
src, dst, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
text = open(src).read()
# The orbit, retimed so that it lasts (n - 1) / 2 s.
times = [float(t) for t in re.findall(r"^t = ([0-9.]+)$", text, re.M)]
scale = ((n - 1) / 2) / times[-1]
text = re.sub(r"^t = ([0-9.]+)$", lambda m: f"t = {float(m.group(1)) * scale!r}", text, flags=re.M)
open(dst, "w").write(text)
PY
flags=(--fps 2 --width "$W" --height "$H" --spp "$SPP" --encode none)
one() { rm -rf "$WORK/one"; "$BIN" film "$ROOT/scenes/cubes.toml" "$WORK/flight.toml" -o "$WORK/one" "${flags[@]}" > /dev/null 2>&1; }
ray_run() { rm -rf "$WORK/cluster"; python3 "$ROOT/tools/ray_film.py" "$ROOT/scenes/cubes.toml" "$WORK/flight.toml" \
  -o "$WORK/cluster" --address 127.0.0.1:6381 --lensview "$BIN" --chunk 1 "${flags[@]}" > "$WORK/driver.log" 2>&1 & wait $!; }
for r in $(seq 1 "$ROUNDS"); do
  for what in one ray_run; do
    if (( r % 2 == 0 )); then what=$([[ $what == one ]] && echo ray_run || echo one); fi
    s=$(date +%s.%N); $what || { cat "$WORK/driver.log"; exit 1; }; e=$(date +%s.%N)
    n=$(ls "$WORK/$([[ $what == one ]] && echo one || echo cluster)" | grep -c '^frame-')
    python3 -c "import sys; w,s,e,n=sys.argv[1],float(sys.argv[2]),float(sys.argv[3]),int(sys.argv[4]); t=e-s; print(f'round $r {w:8s} {n} frames in {t:.1f} s: {3600*n/t:.0f} frames/hour')" "$what" "$s" "$e" "$n"
  done
done
