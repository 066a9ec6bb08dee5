#!/usr/bin/env python3
"""Intel Embree (through the `embreex` Python package, Embree 4) against
lensview on the same primary rays of the same scene, in one run.

Embree gets the scene as triangles: each cuboid as 12 triangles, the lens as
two finely tessellated spherical caps (the same geometry as DESIGN.md §2).
The rays are the camera's pixel-centre rays at WIDTH×HEIGHT, built with the
camera model of core/src/camera.rs. Embree casts them with `EmbreeScene.run`
(closest hit), in as many threads as there are cores (each on its own slice
of the rays), and the best of the two (one thread or all) is reported, median
of RUNS. lensview is measured by `lensview bench --primary-only`, its own
closest-hit throughput on the same rays, also the median of RUNS.

The two alternate for ROUNDS rounds (lensview first, after a pause), and the
ratio reported is the median of the rounds' ratios: on a shared machine a
slow spell then falls on one round, not on one side of the comparison, and
Embree's worker threads have gone idle before lensview is timed.

Optional (needs Python ≥ 3.11): python3 -m pip install embreex numpy
Run from the repository root:  python3 benches/embree_compare.py [SCENE] [--width W --height H --runs N --rounds K]
"""
import argparse
import math
import os
import statistics
import subprocess
import sys
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor

try:
    import numpy as np
    from embreex import rtcore_scene as rtcs
    from embreex.mesh_construction import TriangleMesh
except ImportError as e:  # pragma: no cover - an optional tool
    sys.exit(f"embree_compare: {e}; install with: python3 -m pip install embreex numpy")


def rotation(deg):
    """R = Ry·Rx·Rz from degrees about x, y, z (core/src/math.rs)."""
    x, y, z = (math.radians(a) for a in deg)
    rx = np.array([[1, 0, 0], [0, math.cos(x), -math.sin(x)], [0, math.sin(x), math.cos(x)]])
    ry = np.array([[math.cos(y), 0, math.sin(y)], [0, 1, 0], [-math.sin(y), 0, math.cos(y)]])
    rz = np.array([[math.cos(z), -math.sin(z), 0], [math.sin(z), math.cos(z), 0], [0, 0, 1]])
    return ry @ rx @ rz


def look_angles(d):
    d = d / np.linalg.norm(d)
    return [math.degrees(math.asin(max(-1.0, min(1.0, d[1])))), math.degrees(math.atan2(-d[0], -d[2])), 0.0]


def cuboid_triangles(size, pos, rot_deg):
    h = np.array(size, dtype=float) / 2
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float) * h
    corners = corners @ rotation(rot_deg).T + np.array(pos, dtype=float)
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = []
    for a, b, c, d in faces:
        tris += [(corners[a], corners[b], corners[c]), (corners[a], corners[c], corners[d])]
    return tris


def cap_triangles(center, axis, d, r, sign, rings=64, segments=256):
    """The face of the lens facing sign·axis: sphere centre C − sign·a·√(r²−(d/2)²)."""
    a = np.array(axis, dtype=float)
    a /= np.linalg.norm(a)
    u = np.cross(a, [1.0, 0, 0] if abs(a[0]) < 0.9 else [0, 1.0, 0])
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    half = d / 2
    sc = np.array(center, dtype=float) - sign * a * math.sqrt(max(r * r - half * half, 0.0))
    theta_max = math.asin(min(1.0, half / r))

    def point(i, j):
        th = theta_max * i / rings
        ph = 2 * math.pi * j / segments
        return sc + r * (math.cos(th) * sign * a + math.sin(th) * (math.cos(ph) * u + math.sin(ph) * v))

    tris = []
    for i in range(rings):
        for j in range(segments):
            p00, p01 = point(i, j), point(i, j + 1)
            p10, p11 = point(i + 1, j), point(i + 1, j + 1)
            if i > 0:
                tris.append((p00, p10, p11))
            tris.append((p00, p11, p01))
    return tris


def scene_triangles(sc):
    tris = []
    for o in sc.get("objects", []):
        if o["type"] != "cuboid":
            sys.exit("embree_compare: only cuboids and lenses are meshed here")
        tris += cuboid_triangles(o["size"], o.get("position", [0, 0, 0]), o.get("rotation", [0, 0, 0]))
    for l in sc.get("lenses", []):
        tris += cap_triangles(l["center"], l.get("axis", [0, 0, 1]), l["d"], l["r1"], +1)
        tris += cap_triangles(l["center"], l.get("axis", [0, 0, 1]), l["d"], l["r2"], -1)
    return np.array(tris, dtype=np.float32)


def camera_rays(cam, w, h):
    pos = np.array(cam["position"], dtype=float)
    if "look_at" in cam:
        rot = look_angles(np.array(cam["look_at"], dtype=float) - pos)
    else:
        rot = cam.get("rotation", [0, 0, 0])
    r = rotation(rot)
    tan = math.tan(math.radians(cam.get("fov", 45.0)) / 2)
    xs = (2 * (np.arange(w) + 0.5) / w - 1) * tan * (w / h)
    ys = (1 - 2 * (np.arange(h) + 0.5) / h) * tan
    gx, gy = np.meshgrid(xs, ys)
    local = np.stack([gx.ravel(), gy.ravel(), -np.ones(w * h)], axis=1)
    dirs = local @ r.T
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    origins = np.broadcast_to(pos, dirs.shape)
    return np.ascontiguousarray(origins, dtype=np.float32), np.ascontiguousarray(dirs, dtype=np.float32)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", nargs="?", default="scenes/cubes.toml")
    ap.add_argument("--width", type=int, default=1280)
    ap.add_argument("--height", type=int, default=720)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    with open(args.scene, "rb") as f:
        sc = tomllib.load(f)
    tris = scene_triangles(sc)
    origins, dirs = camera_rays(sc["camera"], args.width, args.height)
    n = len(origins)
    scene = rtcs.EmbreeScene()
    TriangleMesh(scene, tris)
    scene.run(origins[:1024], dirs[:1024])  # build the BVH outside the timing
    cores = os.cpu_count() or 1

    def cast(threads):
        if threads == 1:
            return scene.run(origins, dirs)
        parts = np.array_split(np.arange(n), threads)
        with ThreadPoolExecutor(threads) as ex:
            return list(ex.map(lambda p: scene.run(origins[p[0]:p[-1] + 1], dirs[p[0]:p[-1] + 1]), parts))

    def embree_best():
        best = {}
        for threads in sorted({1, cores}):
            times = []
            for _ in range(args.runs):
                t = time.perf_counter()
                cast(threads)
                times.append(time.perf_counter() - t)
            best[threads] = n / statistics.median(times)
        return best

    exe = os.path.join("target", "release", "lensview")
    subprocess.run(["cargo", "build", "--release", "--quiet"], check=True)

    def lensview():
        out = subprocess.run(
            [exe, "bench", args.scene, "--primary-only", "--width", str(args.width), "--height", str(args.height),
             "--runs", str(args.runs)],
            check=True, capture_output=True, text=True,
        ).stdout
        figures = dict(l.split()[:2] for l in out.splitlines() if l.startswith("primary_rays_per_s"))
        return float(figures["primary_rays_per_s"]), float(figures["primary_rays_per_s_scalar"])

    hits = int((scene.run(origins, dirs) >= 0).sum())
    print(f"scene {args.scene}: {len(tris)} triangles for Embree; {n} primary rays ({args.width}×{args.height}), {hits} hit")
    ratios, scalar_ratios = [], []
    for r in range(1, args.rounds + 1):
        time.sleep(1.0)
        ours, scalar = lensview()
        best = embree_best()
        embree_threads, embree = max(best.items(), key=lambda kv: kv[1])
        ratios.append(ours / embree)
        scalar_ratios.append(scalar / embree)
        print(f"round {r}:")
        for t, rate in sorted(best.items()):
            print(f"  Embree (embreex), {t} thread(s): {rate / 1e6:8.2f} M rays/s")
        print(f"  Embree best ({embree_threads} thread(s)):  {embree / 1e6:8.2f} M rays/s")
        print(f"  lensview ({cores} threads), tiles:         {ours / 1e6:8.2f} M rays/s")
        print(f"  lensview ({cores} threads), one by one:   {scalar / 1e6:8.2f} M rays/s")
        print(f"  ratio lensview / Embree:          {ours / embree:8.2f}× (one by one {scalar / embree:.2f}×)")
    print(f"median ratio over {args.rounds} rounds: {statistics.median(ratios):.2f}× "
          f"(one by one {statistics.median(scalar_ratios):.2f}×); rounds {', '.join(f'{x:.2f}' for x in ratios)}")


if __name__ == "__main__":
    main()
