#!/usr/bin/env python3
"""Render a lensview film on a Ray cluster (README, "Films on many machines").

The driver asks `lensview film --plan` which frames of the film are still
missing in the output folder, splits them into ranges of at most --chunk
frames, and runs one Ray task a range. Each task writes the scene and the
flight it was sent into a temporary folder on its worker, runs
`lensview film SCENE FLIGHT -o TMP --frames A..B` there, and returns the
frames' bytes; the driver writes each frame into the output folder
atomically (a temporary name, then a rename), never over a frame already
there. A task whose worker dies, or whose lensview fails, is retried (Ray's
own retries, then the driver's, --retries in all); a range that still fails
is reported and the driver exits 1. Frames are deterministic (seed, pixel,
sample), so a frame is the same bytes whichever worker made it.

Usage:
  python3 tools/ray_film.py SCENE FLIGHT -o DIR [--address ADDR]
      [--lensview PATH] [--chunk 4] [--retries 3]
      [--fps 30] [--width 1280] [--height 720] [--spp N] [--format png|exr]
      [--seed 0] [--encode mp4|webm|none]

--address: the cluster (`auto` for the one `ray start` made on this
machine; default: a new local one on 127.0.0.1). --lensview: the binary as
the workers see it (the same path on every machine, or on PATH).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("scene")
    p.add_argument("flight")
    p.add_argument("-o", "--output", required=True)
    p.add_argument("--address", default=None)
    p.add_argument("--lensview", default="lensview")
    p.add_argument("--chunk", type=int, default=4)
    p.add_argument("--retries", type=int, default=3)
    p.add_argument("--fps", default="30")
    p.add_argument("--width", default="1280")
    p.add_argument("--height", default="720")
    p.add_argument("--spp", default=None)
    p.add_argument("--format", default="png", choices=["png", "exr"])
    p.add_argument("--seed", default="0")
    p.add_argument("--encode", default="mp4", choices=["mp4", "webm", "none"])
    a = p.parse_args(argv)
    if a.chunk < 1 or a.retries < 0:
        p.error("--chunk must be at least 1 and --retries at least 0")
    return a


def film_flags(a):
    """The flags every `lensview film` of this film gets."""
    flags = ["--fps", a.fps, "--width", a.width, "--height", a.height,
             "--format", a.format, "--seed", a.seed]
    if a.spp is not None:
        flags += ["--spp", a.spp]
    return flags


def plan(a):
    """The film's frame count and the frames missing in the folder."""
    out = subprocess.run(
        [a.lensview, "film", a.scene, a.flight, "-o", a.output, "--plan"] + film_flags(a),
        capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(out.stderr.strip() or "lensview film --plan failed")
    return json.loads(out.stdout)


def ranges(frames, chunk):
    """Runs of consecutive frame numbers, each at most `chunk` long, as
    half-open (start, end) pairs."""
    out = []
    for f in frames:
        if out and out[-1][1] == f and out[-1][1] - out[-1][0] < chunk:
            out[-1][1] = f + 1
        else:
            out.append([f, f + 1])
    return [tuple(r) for r in out]


def render_range(lensview, scene_name, scene_bytes, flight_bytes, flags, start, end, ext):
    """On a worker: frames start..end of the film, as {number: bytes}."""
    with tempfile.TemporaryDirectory(prefix="lensview-film-") as tmp:
        scene = os.path.join(tmp, scene_name)
        flight = os.path.join(tmp, "flight.toml")
        with open(scene, "wb") as f:
            f.write(scene_bytes)
        with open(flight, "wb") as f:
            f.write(flight_bytes)
        frames = os.path.join(tmp, "frames")
        out = subprocess.run(
            [lensview, "film", scene, flight, "-o", frames, "--frames", f"{start}..{end}", "--encode", "none"] + flags,
            capture_output=True, text=True)
        if out.returncode != 0:
            raise RuntimeError(f"frames {start}..{end}: {out.stderr.strip()}")
        got = {}
        for i in range(start, end):
            with open(os.path.join(frames, f"frame-{i:06}.{ext}"), "rb") as f:
                got[i] = f.read()
        return got


def write_frame(dir_, i, ext, data):
    """Writes frame i atomically; a frame already there is kept. True when
    this call wrote it."""
    path = os.path.join(dir_, f"frame-{i:06}.{ext}")
    if os.path.lexists(path):
        return False
    fd, tmp = tempfile.mkstemp(prefix=f".frame-{i:06}.", suffix=".tmp", dir=dir_)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        # link(2) fails if the name exists: a frame is never replaced.
        os.link(tmp, path)
        return True
    except FileExistsError:
        return False
    finally:
        os.unlink(tmp)


def main(argv):
    a = parse_args(argv)
    import ray  # imported here so --help works without Ray

    p = plan(a)
    os.makedirs(a.output, exist_ok=True)
    todo = ranges(p["missing"], a.chunk)
    print(f"film: {p['frames']} frames, {len(p['missing'])} missing, {len(todo)} tasks", flush=True)
    if a.address:
        # A driver on a loopback cluster is on its node 127.0.0.1 (Ray
        # would otherwise look for its raylet at the host's address).
        local = a.address.split(":")[0] in ("127.0.0.1", "localhost")
        extra = {"_node_ip_address": "127.0.0.1"} if local else {}
        ray.init(address=a.address, logging_level="ERROR", **extra)
    else:
        ray.init(_node_ip_address="127.0.0.1", include_dashboard=False, logging_level="ERROR")
    task = ray.remote(max_retries=a.retries, retry_exceptions=True, num_cpus=1)(render_range)
    with open(a.scene, "rb") as f:
        scene_bytes = f.read()
    with open(a.flight, "rb") as f:
        flight_bytes = f.read()
    scene_ref, flight_ref = ray.put(scene_bytes), ray.put(flight_bytes)
    flags = film_flags(a)
    ext = a.format
    start = time.time()

    def submit(r):
        return task.remote(a.lensview, os.path.basename(a.scene), scene_ref, flight_ref, flags, r[0], r[1], ext)

    pending = {submit(r): (r, 0) for r in todo}
    written, failed = 0, []
    while pending:
        done, _ = ray.wait(list(pending), num_returns=1)
        ref = done[0]
        r, tries = pending.pop(ref)
        try:
            frames = ray.get(ref)
        except Exception as e:  # a worker lost past Ray's retries, or lensview failed
            if tries < a.retries:
                print(f"film: frames {r[0]}..{r[1]} failed ({type(e).__name__}); again", flush=True)
                pending[submit(r)] = (r, tries + 1)
            else:
                failed.append((r, str(e).splitlines()[-1] if str(e) else type(e).__name__))
            continue
        for i, data in sorted(frames.items()):
            written += write_frame(a.output, i, ext, data)
        print(f"film: frames {r[0]}..{r[1]} done ({written} written, {time.time() - start:.1f} s)", flush=True)
    ray.shutdown()
    if failed:
        for r, why in failed:
            print(f"film: frames {r[0]}..{r[1]} failed after {a.retries} retries: {why}", file=sys.stderr)
        return 1
    print(f"film: {written} frames written in {time.time() - start:.1f} s → {a.output}", flush=True)
    if a.encode != "none":
        # The encoding (and its check that every frame is there) is the
        # single-machine command's: nothing is missing, so it renders none.
        subprocess.run([a.lensview, "film", a.scene, a.flight, "-o", a.output, "--encode", a.encode] + flags,
                       check=False)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
