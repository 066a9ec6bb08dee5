#!/usr/bin/env python3
"""Writes a scene of N cuboids on a grid (issue 19 item 6: memory per object).

    python3 benches/many-objects.py 100000 > /tmp/c100k.toml
    /usr/bin/time -v lensview render /tmp/c100k.toml -o /tmp/x.png \
        --width 64 --height 48 --spp 1     # "Maximum resident set size"

N = 0 gives the same scene with no object (the fixed cost). Each object is
written in the short inline form, about 70 bytes, so 10^6 objects (70 MB)
fit under the 128 MiB scene-file cap.
tests/memory.rs counts the heap bytes per object in-process.
"""
import math
import sys


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100000
    side = max(1, math.ceil(math.sqrt(n)))
    out = sys.stdout
    # The top-level array comes before the first table header.
    out.write("objects = [\n")
    for i in range(n):
        x, z = i % side - side // 2, i // side - side // 2
        out.write('{type="cuboid",position=[%d,0,%d],size=[0.8,0.8,0.8],material="m"},\n' % (x, z))
    out.write("]\n\n")
    out.write(
        "[render]\nspp = 1\nshadows = true\n\n"
        "[camera]\nposition = [0, %d, %d]\nlook_at = [0, 0, 0]\nfov = 60\n\n"
        '[[lights]]\ntype = "point"\nposition = [0, %d, 0]\nintensity = %d\n\n'
        "[materials.m]\ncolor = [0.6, 0.5, 0.4]\n\n" % (side, side, side, side * side)
    )


if __name__ == "__main__":
    main()
