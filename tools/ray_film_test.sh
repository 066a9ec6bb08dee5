#!/usr/bin/env bash
# The Ray film test (issue #35, run by tests/film_cluster.rs): a local Ray
# cluster of a head and two worker nodes, a film rendered on it by
# tools/ray_film.py while one worker node is killed mid-run, and every frame
# checked to be there once and byte-identical to the single-machine film.
#
# It runs in its own network and PID namespaces (`unshare --net --pid`, as
# root): the only network there is the loopback, so whatever Ray listens on
# (its GCS and raylets bind every interface) is reachable from 127.0.0.1
# only, and when this script ends every process it started ends with it.
#
# Usage: tools/ray_film_test.sh LENSVIEW SCENE FLIGHT WORKDIR
set -euo pipefail
if [[ ${LENSVIEW_IN_NS:-} != 1 ]]; then
  exec env LENSVIEW_IN_NS=1 unshare --net --pid --fork --mount-proc bash "$0" "$@"
fi
BIN=$1; SCENE=$2; FLIGHT=$3; WORK=$4
# A step that fails says which, rather than ending the test without a word.
trap 'rc=$?; echo "FAIL: line $LINENO: \`$BASH_COMMAND\` exited $rc"' ERR
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/ray_cluster.sh"
rm -rf "$WORK"; mkdir -p "$WORK"
PORT=6380
start_cluster $PORT "$WORK" 2

# The film on the cluster, a worker node killed once its first task runs.
# The workers run lensview through a wrapper that waits a second before a
# range (the driver's --plan does not wait): the frames are tiny, so without
# it a task could end between two looks and no node would be killed.
flags=(--fps 6 --width 64 --height 36 --spp 2 --encode none)
slow="$WORK/lensview-slow"
printf '#!/bin/sh\ncase " $* " in *" --frames "*) sleep 1 ;; esac\nexec "%s" "$@"\n' "$BIN" > "$slow"
chmod +x "$slow"
python3 "$HERE/ray_film.py" "$SCENE" "$FLIGHT" -o "$WORK/cluster" --address 127.0.0.1:$PORT \
  --lensview "$slow" --chunk 2 --retries 4 "${flags[@]}" > "$WORK/driver.log" 2>&1 &
driver=$!
killed=""
for _ in $(seq 1 1200); do
  # A lensview film started by a worker (the wrapper, in its first second):
  # its raylet is its grandparent.
  pid=$(pgrep -f "lensview-film-.*--frames" | head -1 || true)
  if [[ -n $pid ]]; then
    worker=$(ps -o ppid= -p "$pid" | tr -d ' ')
    raylet=$(ps -o ppid= -p "$worker" | tr -d ' ')
    if [[ $(ps -o comm= -p "$raylet") == raylet ]]; then
      kill -9 "$raylet" "$worker" "$pid" 2>/dev/null || true
      killed=$raylet
      break
    fi
  fi
  sleep 0.05
done
status=0; wait $driver || status=$?
grep -E '^film:' "$WORK/driver.log" || cat "$WORK/driver.log"
[[ -n $killed ]] || { echo "FAIL: no worker node was killed (no task seen running)"; exit 1; }
echo "killed the raylet $killed of a worker node mid-run"
[[ $status == 0 ]] || { echo "FAIL: the driver exited $status; its log:"; tail -n 60 "$WORK/driver.log"; exit 1; }

# The same film on one machine; every frame once, byte for byte.
"$BIN" film "$SCENE" "$FLIGHT" -o "$WORK/single" "${flags[@]}" > /dev/null 2>&1
a=$(cd "$WORK/single" && ls frame-* | sort); b=$(cd "$WORK/cluster" && ls frame-* | sort)
[[ "$a" == "$b" ]] || { echo "FAIL: frames differ: single [$a] cluster [$b]"; exit 1; }
for f in $a; do cmp "$WORK/single/$f" "$WORK/cluster/$f"; done
leftover=$(ls -A "$WORK/cluster" | grep -v '^frame-' || true)
[[ -z $leftover ]] || { echo "FAIL: left in the folder: $leftover"; exit 1; }
echo "OK: $(echo "$a" | wc -l) frames, each once, identical to the single-machine film"
