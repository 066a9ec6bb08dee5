#!/usr/bin/env bash
# What a feature that a scene does not use costs it, counted in instructions
# rather than timed: for each feature, one frame of the cubes scene without
# that feature, rendered by the kernel that leaves it out (what lensview runs)
# and by the kernel with every feature compiled in (what a renderer that does
# not specialise would run). Counted by valgrind's callgrind on one thread, so
# the figures do not move with the load of a shared machine the way times do.
# A frame's count is the difference between runs of 2 and 1 frames (start-up
# cancels out).
#
# Optional (needs valgrind: apt-get install valgrind). Run from the repository
# root:  benches/feature-instructions.sh   (W=160 H=120 by default)
set -euo pipefail
W=${W:-160}
H=${H:-120}
command -v valgrind >/dev/null || { echo "feature-instructions: needs valgrind (apt-get install valgrind)" >&2; exit 1; }
cargo build --release --quiet
exe=target/release/lensview

count() { # feature, kernel flag (or empty), frames
    RAYON_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file=/dev/null \
        "$exe" bench --unused-feature "$1" ${2:+"$2"} --frames "$3" --width "$W" --height "$H" 2>&1 |
        sed -n 's/.*Collected : *\([0-9][0-9]*\).*/\1/p'
}

echo "instructions per ${W}×${H} frame of the cubes scene without the feature (1 thread)"
printf "%-11s %15s %15s %10s\n" feature "left out" "compiled in" overhead
for f in shadows glass mirror specular dispersion; do
    s=$(( $(count "$f" "" 2) - $(count "$f" "" 1) ))
    u=$(( $(count "$f" --unspecialised 2) - $(count "$f" --unspecialised 1) ))
    awk -v f="$f" -v s="$s" -v u="$u" 'BEGIN { printf "%-11s %15d %15d %9.2f%%\n", f, s, u, 100 * (u / s - 1) }'
done
