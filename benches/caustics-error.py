#!/usr/bin/env python3
"""Error against run time of the caustic estimate, for several lensview
builds side by side (issue 29.3: "at the same caustic accuracy").

  benches/caustics-error.py REF_BINARY SCENE.toml --bins OLD NEW
      [--spp 4,16,64] [--ref-spp 256] [--ref-seed 1] [--size 640x360]
      [--threads 1] [--ref-cache DIR]

For each scene: a reference (REF_BINARY at --ref-spp, EXR), the same scene
without caustics (benches/caustics-off.py) at --ref-spp, and each binary at
each --spp (EXR, seed 0, so the camera samples are the same in every build
and only the caustic estimate differs). Prints, per binary and sample
count, the wall time of the render (as `render` reports it) and the RMS
error against the reference in linear RGB over every pixel and over the
caustic's pixels (where the reference with caustics exceeds the one
without by more than 2 % of the brighter's 99th percentile). Binaries
alternate within each sample count. The reference is rendered from
another seed (--ref-seed) than the binaries (seed 0): with the same seed
its first photon passes would be theirs (a build whose passes spread
evenly would then look closer than it is). Needs numpy and mitsuba (to read EXR):
run it with the venv of benches/mitsuba_speed.py. With --ref-cache the
references are kept in DIR and taken from there on later runs (only from
the same REF_BINARY: the file names do not say which binary made them).
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")
HERE = os.path.dirname(os.path.abspath(__file__))
TIME = re.compile(r"in ([\d.]+) s \(")


def render(binary, scene, out, size, spp, threads, seed=0):
    w, h = size.split("x")
    cmd = [binary, "render", scene, "--width", w, "--height", h, "--spp", str(spp), "--seed", str(seed), "-o", out]
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    run = subprocess.run(cmd, env=env, check=True, capture_output=True, text=True)
    m = TIME.search(run.stdout + run.stderr)
    if not m:
        sys.exit(f"no time in: {run.stdout}{run.stderr}")
    return float(m.group(1))


def load(path):
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def rms(a, b, where=None):
    d = (a - b) ** 2
    if where is not None:
        d = d[where]
    return float(np.sqrt(d.mean()))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("ref_binary")
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--bins", nargs="+", required=True)
    ap.add_argument("--spp", default="4,16,64")
    ap.add_argument("--ref-spp", type=int, default=256)
    ap.add_argument("--ref-seed", type=int, default=1)
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--ref-cache", help="folder to keep the references in and take them from (keyed by scene, size, spp and seed)")
    a = ap.parse_args()
    model = next(
        (ln.split(":", 1)[1].strip() for ln in subprocess.run(["lscpu"], capture_output=True, text=True).stdout.splitlines() if ln.startswith("Model name")),
        "?",
    )
    print(f"CPU: {model}; {a.size}, {a.threads} thread(s), reference {a.ref_binary} at {a.ref_spp} spp, seed {a.ref_seed}")
    with tempfile.TemporaryDirectory() as tmp:
        for scene in a.scenes:
            name = os.path.splitext(os.path.basename(scene))[0]
            off_toml = os.path.join(tmp, f"{name}-off.toml")
            subprocess.run([sys.executable, os.path.join(HERE, "caustics-off.py"), scene, off_toml], check=True)
            keep = a.ref_cache or tmp
            os.makedirs(keep, exist_ok=True)
            stem = os.path.join(keep, f"{name}-{a.size}-{a.ref_spp}spp-seed{a.ref_seed}")
            ref, ref_off = stem + ".exr", stem + "-off.exr"
            for toml, out in [(scene, ref), (off_toml, ref_off)]:
                if not (a.ref_cache and os.path.exists(out)):
                    render(a.ref_binary, toml, out, a.size, a.ref_spp, os.cpu_count(), a.ref_seed)
            r, r_off = load(ref), load(ref_off)
            lum = r.mean(axis=2)
            caustic = (r - r_off).mean(axis=2) > 0.02 * np.percentile(lum, 99)
            print(f"\n{name}: {int(caustic.sum())} caustic pixels of {caustic.size}")
            print(f"{'spp':>5}  {'binary':<28} {'time s':>8} {'RMS all':>10} {'RMS caustic':>12}")
            for spp in [int(s) for s in a.spp.split(",")]:
                for b in a.bins:
                    out = os.path.join(tmp, "x.exr")
                    t = render(b, scene, out, a.size, spp, a.threads)
                    img = load(out)
                    e_all, e_c = rms(img, r), rms(img, r, caustic) if caustic.any() else float("nan")
                    print(f"{spp:>5}  {os.path.basename(b):<28} {t:>8.3f} {e_all:>10.5f} {e_c:>12.5f}")


if __name__ == "__main__":
    main()
