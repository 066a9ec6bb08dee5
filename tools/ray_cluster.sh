# Sourced by tools/ray_film_test.sh and benches/film-throughput.sh, inside
# their own network and PID namespaces (`unshare --net --pid --fork
# --mount-proc`, as root): the loopback up, and a local Ray cluster of a head
# (no CPUs: it schedules) and NODES worker nodes of one CPU each, on PORT,
# logs under WORK. Ray listens on every interface of the namespace, which
# has only the loopback.
ray() { python3 -m ray.scripts.scripts "$@"; }
start_cluster() {
  local port=$1 work=$2 nodes=$3
  python3 -c 'import ray' || { echo "FAIL: Ray is not installed for $(command -v python3) (python3 -m pip install ray)"; exit 1; }
  ip link set lo up
  export RAY_USAGE_STATS_ENABLED=0
  # A dead node is noticed within about five seconds, and a live one on a
  # busy machine (a missed beat or two) is not taken for dead.
  export RAY_health_check_period_ms=1000 RAY_health_check_timeout_ms=1000 RAY_health_check_failure_threshold=5
  local common=(--node-ip-address=127.0.0.1 --object-store-memory=200000000 --disable-usage-stats)
  # Ray's session folder holds its Unix sockets, whose paths may not pass
  # 107 bytes: it goes under a short folder of its own in /tmp, not under
  # WORK (a checkout's target/tmp can be deep), and is removed at the end.
  RAY_TMP=$(mktemp -d /tmp/lvray.XXXXXX)
  trap 'ray stop --force >/dev/null 2>&1 || true; rm -rf "$RAY_TMP"' EXIT
  ray start --head --port="$port" --num-cpus=0 --include-dashboard=false --temp-dir="$RAY_TMP" "${common[@]}" > "$work/head.log" 2>&1 \
    || { echo "FAIL: the Ray head did not start; the end of its log:"; tail -n 20 "$work/head.log"; exit 1; }
  for n in $(seq 1 "$nodes"); do
    ray start --address=127.0.0.1:"$port" --num-cpus=1 "${common[@]}" > "$work/node$n.log" 2>&1 \
      || { echo "FAIL: Ray worker node $n did not start; the end of its log:"; tail -n 20 "$work/node$n.log"; exit 1; }
  done
  echo "cluster up: $nodes worker nodes; listening on: $(ss -ltnH | awk '{print $4}' | sed 's/:[0-9]*$//' | sort -u | tr '\n' ' ')"
}
