#!/usr/bin/env python3
"""RSS growth of a soak run (benches/soak.sh): reads OUT/rss.csv,
OUT/checkpoints.csv and OUT/frames.jsonl, prints the summary and a last
line `growth ok` or `growth FAIL`.

    python3 benches/soak_rss.py OUT [core/src/limits.rs]

RSS follows the size of the picture being refined: the progressive
renderer keeps PROGRESSIVE_BYTES_PER_PIXEL bytes a rendered pixel
(core/src/limits.rs, read from there), and the soak changes the window's size,
the resolution (a key) and the panel's width. So each checkpoint (the
window back at 1100x700, RSS read 3 s later) is judged less those buffers
at the render size the frame log shows then. A leak raises the floor: the
last quarter's lowest such value over the second quarter's lowest > 1.25
fails. Raw checkpoints and the medians are printed too.
"""
import csv, json, re, statistics, sys

out = sys.argv[1]
limits = sys.argv[2] if len(sys.argv) > 2 else "core/src/limits.rs"
m = re.search(r"pub const PROGRESSIVE_BYTES_PER_PIXEL: u64 = ([^;]+);", open(limits).read())
bpp = eval(m.group(1), {})  # an arithmetic expression of integers


def read(path):
    return [(int(r["t_s"]), int(r["rss_kb"])) for r in csv.DictReader(open(path))]


rows, checks = read(f"{out}/rss.csv"), read(f"{out}/checkpoints.csv")
frames = [json.loads(line) for line in open(f"{out}/frames.jsonl")]
print(f"rss samples: {len(rows)} at every size; start {rows[0][1] / 1024:.1f} MiB, end {rows[-1][1] / 1024:.1f} MiB, "
      f"peak {max(v for _, v in rows) / 1024:.1f} MiB")
adjusted, sizes = [], []
for t, kb in checks:
    shown = [f for f in frames if f["t"] <= t + 0.5]
    w, h = (shown[-1]["width"], shown[-1]["height"]) if shown else (0, 0)
    sizes.append(f"{w}x{h}")
    adjusted.append(kb * 1024 - bpp * w * h)
n = len(checks)
q = max(n // 4, 1)
mib = lambda v: f"{v / 2**20:.0f}"
print(f"checkpoints at 1100x700: {n}; RSS {', '.join(mib(kb * 1024) for _, kb in checks)} MiB at render sizes "
      f"{', '.join(sizes)}; less {bpp} bytes a rendered pixel: {', '.join(mib(v) for v in adjusted)} MiB")
second, last = adjusted[q:2 * q], adjusted[-q:]
low = min(last) / min(second)
print(f"last quarter / 2nd quarter (less the picture's buffers): lowest {low:.3f}, "
      f"median {statistics.median(last) / statistics.median(second):.3f}")
print(f"growth {'FAIL' if low > 1.25 else 'ok'}")
