#!/usr/bin/env python3
"""Times lensview against Mitsuba 3 (`scalar_rgb`) on the same scene, 1 spp.

Not run in CI. Needs `pip install mitsuba numpy` (a venv outside the repo).

The scene: the flat-colour version of each scene that benches/
mitsuba_compare.py compares (its conversion, reused): every object a
constant colour, the lens glass. lensview renders it as a Whitted frame
(ambient only: no lights, so no shadow rays and no caustic photons; the
exact lens, its reflections inside followed to the scene's `max_depth`).
Mitsuba renders it with the `path` integrator, `max_depth` the scene's + 1
(mitsuba_compare.py's mapping: the same paths), each cuboid a `cube` shape
with an area emitter of its colour, the background a constant
environment, the lens a smooth-shaded tessellated `dielectric` mesh
(RINGS × SEGMENTS a cap). Under each emitter a black BSDF:
  --mi-surface delta   (default) a black smooth conductor: the path ends at
                       the surface, with no emitter sample, as lensview's
                       flat shading does (equal work).
  --mi-surface diffuse mitsuba_compare.py's black diffuse: Mitsuba also
                       samples an emitter (one shadow ray) at every hit.
Only cuboid scenes with single lenses are supported (cubes, focal-spot,
optical-bench, rim-lens), not lens systems or lens cameras.

What is timed: one 1-spp frame at WIDTH×HEIGHT (400×400), nothing else.
Mitsuba: `mi.render(scene, spp=1)` (film, blocks, develop), the scene
loaded and its BVH built beforehand (reported apart), one untimed warm-up
render. lensview: `lensview bench SCENE --frame-only --runs RUNS` (the
scene parsed and its BVH built beforehand, one untimed warm-up frame,
then RUNS frames into the kept image, as the viewer renders). Both use
THREADS threads (default: every core): lensview through RAYON_NUM_THREADS,
Mitsuba through `drjit.set_thread_count` (its scalar render runs on Dr.Jit's
nanothread pool: the calling thread and THREADS − 1 workers; Mitsuba's log
line counts one more).

The two alternate for ROUNDS rounds, in one run (lensview first, after a
pause): each round RUNS frames of each, its median. Every round is printed;
the ratio reported (Mitsuba time / lensview time) is the median of the
rounds' ratios, and the ratio of the fastest frames. Also the CPU time a
frame (the process's, every thread, spin-waits included): on a shared
machine it moves less than wall time. Mitsuba's: `time.process_time`
around its RUNS renders. lensview's: the CPU time of the bench process
with RUNS frames less that of one with a single frame (each parses, builds
and renders a warm-up frame), over RUNS − 1.

Usage:
  benches/mitsuba_speed.py LENSVIEW_BINARY SCENE.toml [SCENE.toml ...]
      [--width 400 --height 400 --rounds 5 --runs 10 --threads N]
      [--rings 64 --segments 256] [--mi-surface delta|diffuse]
      [--mi-max-depth scene|N] [--pause 1.0]
"""

import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mitsuba_compare import flat, mitsuba_depth, mitsuba_scene, to_toml  # noqa: E402

FRAME = re.compile(r"^frame (\d+)x(\d+) \((\d+) threads, (\d+) runs\): fastest ([\d.]+) ms, median ([\d.]+) ms(.*)$")


def cpu_line():
    """lscpu's model name and whether the CPU has AVX-512F."""
    out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    model = next((ln.split(":", 1)[1].strip() for ln in out.splitlines() if ln.startswith("Model name")), "?")
    flags = set()
    with open("/proc/cpuinfo") as f:
        for ln in f:
            if ln.startswith("flags"):
                flags = set(ln.split(":", 1)[1].split())
                break
    return f"CPU: {model}, {os.cpu_count()} logical CPUs, avx512f: {'yes' if 'avx512f' in flags else 'no'}"


def load():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def supported(path, scene):
    if scene.get("systems"):
        sys.exit(f"{path}: lens systems are not supported")
    if any(k in scene.get("camera", {}) for k in ("lens", "system")):
        sys.exit(f"{path}: lens cameras are not supported")
    lenses = scene.get("lenses", [])
    if any(isinstance(lens.get("n"), (list, dict)) for lens in lenses):
        sys.exit(f"{path}: dispersive lenses are not supported")
    return flat(scene)  # exits on a non-cuboid object


def lensview_frames(binary, toml, a, runs):
    """`lensview bench --frame-only` with RUNS frames: (fastest s, median s,
    the lane build, the process's CPU seconds, all threads)."""
    env = dict(os.environ, RAYON_NUM_THREADS=str(a.threads))
    cmd = [binary, "bench", toml, "--frame-only", "--width", str(a.width), "--height", str(a.height)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run(cmd + ["--runs", str(runs)], env=env, check=True, capture_output=True, text=True).stdout
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    for ln in out.splitlines():
        m = FRAME.match(ln)
        if m and (int(m[1]), int(m[2])) == (a.width, a.height):
            if int(m[3]) != a.threads:
                sys.exit(f"lensview ran {m[3]} threads, not {a.threads}")
            return float(m[5]) / 1e3, float(m[6]) / 1e3, m[7].strip(), cpu
    sys.exit(f"no {a.width}x{a.height} frame line in: {out}")


def lensview_round(binary, toml, a):
    """One round of lensview: (fastest, median, CPU a frame) in seconds, the
    lane build. The CPU time a frame: that of a run of RUNS frames less that
    of a run of one (both parse the scene, build its BVH and render a
    warm-up frame), over RUNS − 1."""
    fastest, median, lanes, cpu = lensview_frames(binary, toml, a, a.runs)
    cpu1 = lensview_frames(binary, toml, a, 1)[3]
    return fastest, median, (cpu - cpu1) / (a.runs - 1), lanes


def mitsuba_round(mi, scene, a):
    """One round of Mitsuba frames: (fastest, median, mean CPU) in seconds
    (CPU: the process's, all threads)."""
    times, cpu = [], time.process_time()
    for _ in range(a.runs):
        t = time.perf_counter()
        mi.render(scene, spp=1)
        times.append(time.perf_counter() - t)
    cpu = (time.process_time() - cpu) / a.runs
    times.sort()
    return times[0], times[len(times) // 2], cpu


def compare(mi, binary, path, a):
    with open(path, "rb") as f:
        scene = supported(path, tomllib.load(f))
    name = os.path.basename(path)
    with tempfile.TemporaryDirectory() as tmp:
        toml = os.path.join(tmp, "flat.toml")
        with open(toml, "w") as f:
            f.write(to_toml(scene))
        depth = mitsuba_depth(scene, a.mi_max_depth)
        d, tris = mitsuba_scene(mi, scene, a.width, a.height, 1, a.rings, a.segments, tmp, depth, a.mi_surface)
        t = time.perf_counter()
        mscene = mi.load_dict(d)
        loaded = time.perf_counter() - t
        mi.render(mscene, spp=1)  # warm-up
        print(
            f"\n{name}: {a.width}x{a.height}, 1 spp, {a.threads} threads; Mitsuba {mi.variant()} path "
            f"max_depth {depth}, surfaces {a.mi_surface}, lens {tris} triangles, scene loaded in {loaded:.2f} s",
            flush=True,
        )
        print(
            "round  load avg        lensview fastest / median (CPU) ms   Mitsuba fastest / median (CPU) ms"
            "   ratio: medians (CPU)"
        )
        ratios, cpu_ratios, lv_best, mi_best = [], [], float("inf"), float("inf")
        for r in range(a.rounds):
            time.sleep(a.pause)
            before = load()
            lf, lm, lc, lanes = lensview_round(binary, toml, a)
            time.sleep(a.pause)
            mf, mm, mc = mitsuba_round(mi, mscene, a)
            ratios.append(mm / lm)
            cpu_ratios.append(mc / lc)
            lv_best, mi_best = min(lv_best, lf), min(mi_best, mf)
            print(
                f"{r + 1:>5}  {before:<14}  {lf * 1e3:7.2f} / {lm * 1e3:7.2f} ({lc * 1e3:7.2f})           "
                f"{mf * 1e3:7.2f} / {mm * 1e3:7.2f} ({mc * 1e3:7.2f})          {mm / lm:6.2f}× ({mc / lc:6.2f}×)",
                flush=True,
            )
        print(
            f"{name}: lensview {lanes}; Mitsuba / lensview: median of the rounds' ratios {statistics.median(ratios):.2f}× "
            f"(range {min(ratios):.2f}–{max(ratios):.2f}×), of CPU times {statistics.median(cpu_ratios):.2f}× "
            f"(range {min(cpu_ratios):.2f}–{max(cpu_ratios):.2f}×); fastest frames {mi_best * 1e3:.2f} / "
            f"{lv_best * 1e3:.2f} ms = {mi_best / lv_best:.2f}×; load avg after: {load()}",
            flush=True,
        )


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("binary")
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--width", type=int, default=400)
    ap.add_argument("--height", type=int, default=400)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--runs", type=int, default=10, help="frames of each renderer a round (its median), at least 2")
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--rings", type=int, default=64)
    ap.add_argument("--segments", type=int, default=256)
    ap.add_argument("--mi-surface", choices=("delta", "diffuse"), default="delta")
    ap.add_argument("--mi-max-depth", default="scene", help='"scene" (the scene\'s max_depth + 1) or a number')
    ap.add_argument("--pause", type=float, default=1.0, help="seconds of pause before each side of a round")
    a = ap.parse_args()
    if a.runs < 2:
        ap.error("--runs: at least 2")
    import drjit as dr
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    dr.set_thread_count(a.threads)
    print(cpu_line())
    print(f"Mitsuba {mi.__version__} ({mi.variant()}), lensview {a.binary}; load avg at start: {load()}")
    for path in a.scenes:
        compare(mi, a.binary, path, a)


if __name__ == "__main__":
    main()
