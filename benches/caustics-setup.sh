# Sourced by caustics-cost.sh and caustics-paired.sh (not run alone), after
# they set SIZE: the frame's W and H, the scenes (the shipped ones whose
# caustics are on; CAUSTIC_SCENES overrides), the project root `here`, the
# machine's name, its avx512f flag and load, and a temporary folder `dir`
# (removed on exit) holding each scene's copy with `[render] caustics =
# false` as `$dir/SCENE-off.toml`.
W=${SIZE%x*}; H=${SIZE#*x}
SCENES=${CAUSTIC_SCENES:-"cubes focal-spot lens-family optical-bench primitives rim-lens"}
benches=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
here=$(dirname "$benches")
lscpu | grep 'Model name' || true
grep -q avx512f /proc/cpuinfo && echo "avx512f: yes" || echo "avx512f: no"
uptime
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
for s in $SCENES; do
  python3 "$benches/caustics-off.py" "$here/scenes/$s.toml" "$dir/$s-off.toml"
done
