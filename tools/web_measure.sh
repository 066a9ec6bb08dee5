#!/usr/bin/env bash
# The figures of docs/web.md: a 1-spp frame of cubes at 1280×720 in the page
# (headless Chromium; threads when served with COOP/COEP, one thread
# without) and natively (portable and best kernel, one and all threads), on
# the same machine in one run; the page's sizes and its time to the first
# picture. Needs a built page (web/build.sh, or DIST) and
# `cargo build --release`. Usage: tools/web_measure.sh [RUNS] [DIST]
set -euo pipefail
cd "$(dirname "$0")/.."
runs="${1:-3}"
dist="${2:-web/dist}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
lscpu | grep 'Model name'
echo "cores: $(nproc); load: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "wasm: $(stat -c %s $dist/pkg/lensview_web_bg.wasm) bytes raw, $(gzip -9 -c $dist/pkg/lensview_web_bg.wasm | wc -c) gzip -9;" \
    "js: $(stat -c %s $dist/pkg/lensview_web.js) raw, $(gzip -9 -c $dist/pkg/lensview_web.js | wc -c) gzip -9"
for i in $(seq "$runs"); do
    for iso in "" --no-isolation; do
        python3 tools/web_page_test.py --dist "$dist" --out "$out/p$i" --measure $iso \
            --query "scene=cubes&w=1280&h=720&spp=1" > /dev/null
        python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['first']; print(f\"page ${iso:-isolated} 1280x720 1 spp, {r['threads']} threads: {r['renderMs']/1000:.3f} s from start to the finished picture ({r['previewMs']/1000:.3f} s block previews, {r['samplesMs']/1000:.3f} s the sample; the rest photons and drawing); first preview {r['firstFrameMs']/1000:.3f} s, first 1-spp picture {r['firstPictureMs']/1000:.3f} s after navigation\")" "$out/p$i/report.json"
    done
    python3 tools/web_page_test.py --dist "$dist" --out "$out/d$i" --measure --query "" > /dev/null
    python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['first']; print(f\"page default (cubes 640x480, 4 spp), {r['threads']} threads: first preview {r['firstFrameMs']/1000:.3f} s, first 1-spp picture {r['firstPictureMs']/1000:.3f} s after navigation, all 4 spp {r['renderMs']/1000:.3f} s after start\")" "$out/d$i/report.json"
    for isa in portable ""; do
        for threads in 1 ""; do
            line="$(RAYON_NUM_THREADS=$threads LENSVIEW_ISA=$isa target/release/lensview render scenes/cubes.toml \
                --width 1280 --height 720 --spp 1 -o "$out/n.png" | tail -1)"
            echo "native ISA=${isa:-best} threads=${threads:-all}: $line"
        done
    done
done
