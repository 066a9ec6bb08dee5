#!/usr/bin/env bash
# Soak test of the real viewer window under Xvfb (Mesa lavapipe) for N
# minutes: random keys from the binding table (src/viewer/keys.rs), window
# resizes down to 40x30, clicks on the panel's named buttons (--ui-log), F5
# reloads of a copy of scenes/cubes.toml edited on disk (sometimes made
# invalid, then valid again), then the window closes itself (--exit-after).
# It reports RSS over time (CSV), panics, window screenshots (not blank), the
# P renders (pure-black share: where a NaN pixel would show; the frame log
# has no NaN field), the counts and the exit status, and fails (exit 1) on a panic, a non-zero exit,
# a hang past --exit-after + margin (thread stacks saved by gdb), an all-black
# picture, or RSS growth after warm-up: every 45 s the window goes back to
# 1100x700 and, 3 s later, RSS is read (checkpoints.csv); benches/soak_rss.py
# judges those less the progressive renderer's buffers at the render size the
# frame log shows (the soak changes the resolution and the panel too), and
# fails when the last quarter's lowest is over 1.25 times the second
# quarter's. rss.csv keeps every reading.
# Needs xvfb, xdotool, imagemagick and python3; run from the repository root:
#   bash benches/soak.sh [MINUTES] [SEED]
# LENSVIEW=path/to/binary skips the build; SOAK_OUT=dir keeps the logs there;
# SOAK_DISPLAY=:N picks the Xvfb display (else a random one from :200).
set -euo pipefail
minutes=${1:-10}
seed=${2:-$$}
RANDOM=$seed
root=$(pwd)
if [ -z "${LENSVIEW:-}" ]; then
    cargo build --release --quiet
    LENSVIEW=$root/target/release/lensview
fi
out=${SOAK_OUT:-$(mktemp -d)}
mkdir -p "$out"; rm -f "$out"/actions.log "$out"/frames.jsonl "$out"/shot-*.png "$out"/screenshots.txt
tmp=$(mktemp -d)
display=${SOAK_DISPLAY:-:$((200 + RANDOM % 300))}
Xvfb "$display" -screen 0 1920x1200x24 -nolisten tcp -noreset >/dev/null 2>&1 &
xvfb=$!
app=""
cleanup() {
    [ -n "$app" ] && kill "$app" 2>/dev/null || true
    kill "$xvfb" 2>/dev/null || true
    rm -rf "$tmp"
}
trap cleanup EXIT
export DISPLAY=$display XDG_RUNTIME_DIR=$tmp
for _ in $(seq 100); do [ -e "/tmp/.X11-unix/X${display#:}" ] && break; sleep 0.1; done

# The keys: every binding of the table, in xdotool's names, except Esc (quit)
# and the chords that open a file dialog (Open, SaveAs). "hold" for flight.
python3 - "$root/src/viewer/keys.rs" >"$tmp/keys" <<'PY'
import re, sys
src = open(sys.argv[1]).read()
plain = src[src.index("pub const BINDINGS"):src.index("pub const CTRL_BINDINGS")]
ctrl = src[src.index("pub const CTRL_BINDINGS"):src.index("pub fn action_for")]
held = {"Forward", "Back", "Left", "Right", "Down", "Up", "LookLeft", "LookRight", "LookUp", "LookDown"}
names = {"Comma": "comma", "Period": "period", "Minus": "minus", "Equal": "equal",
         "BracketLeft": "bracketleft", "BracketRight": "bracketright", "Space": "space"}
def x(code):
    if code.startswith("Key"): return code[3:].lower()
    if code.startswith("Digit"): return code[5:]
    if code.startswith("Arrow"): return code[5:]
    return names.get(code, code)
n = 0
for code, action in re.findall(r'\(\s*KeyCode::(\w+),\s*"[^"]*",\s*Action::(\w+)', plain):
    if action == "Quit": continue
    print("hold" if action in held else "key", x(code), action); n += 1
for code, shift, action in re.findall(r'\(\s*KeyCode::(\w+),\s*(true|false),\s*"[^"]*",\s*Action::(\w+)', ctrl):
    if action in ("Open", "SaveAs"): continue
    print("key", ("ctrl+shift+" if shift == "true" else "ctrl+") + x(code), action); n += 1
if n < 40: sys.exit(f"only {n} bindings parsed from keys.rs")
PY
mapfile -t keys <"$tmp/keys"

scene=$tmp/soak.toml
cp scenes/cubes.toml "$scene"
cp scenes/cubes.toml "$tmp/original.toml"
budget=$((minutes * 60))
exit_after=$((budget + 10))
margin=30
cd "$tmp"   # P writes its screenshots here
"$LENSVIEW" view "$scene" --width 1100 --height 700 --max-spp 4 \
    --frame-log "$out/frames.jsonl" --ui-log "$tmp/ui.json" \
    --exit-after "$exit_after" >"$out/stdout.txt" 2>"$out/stderr.txt" &
app=$!
start=$(date +%s)
win=""
for _ in $(seq 300); do win=$(xdotool search --name '^lensview' 2>/dev/null | head -1 || true); [ -n "$win" ] && break; sleep 0.1; done
[ -n "$win" ] || { echo "the window did not appear"; cat "$out/stderr.txt"; exit 1; }
xdotool windowfocus --sync "$win" || true

rss() { awk '/^VmRSS/ {print $2}' "/proc/$app/status" 2>/dev/null || true; }
echo "t_s,rss_kb" >"$out/rss.csv"
echo "t_s,rss_kb" >"$out/checkpoints.csv"
last_check=0
checkpoint() { # RSS at the starting size, once the picture has settled
    xdotool windowsize "$win" 1100 700 2>/dev/null || true
    sleep 3
    local r; r=$(rss); [ -n "$r" ] && echo "$(($(date +%s) - start)),$r" >>"$out/checkpoints.csv"
}
nkeys=0 nholds=0 nresizes=0 nclicks=0 nreloads=0 ninvalid=0 nshots=0 blank=0
last_rss=0
edit_scene() { # a valid change of the light's intensity, or (1 in 4) a broken file
    if [ $((RANDOM % 4)) -eq 0 ]; then
        sed 's/^intensity = 500$/intensity = "oops/' "$tmp/original.toml" >"$scene"
        ninvalid=$((ninvalid + 1))
    else
        sed "s/^intensity = 500\$/intensity = $((200 + RANDOM % 600))/" "$tmp/original.toml" >"$scene"
    fi
}
click() { # the middle of a random named button of the panel, if any is on screen
    local at
    at=$(python3 - "$tmp/ui.json" "$RANDOM" <<'PY' || true
import json, sys
try: rects = json.load(open(sys.argv[1]))
except Exception: sys.exit()
names = sorted(n for n in rects if n.startswith(("Add ", "section ", "confirm cancel")) or n == "Undo")
if "confirm cancel" in rects: names = ["confirm cancel"]
if names:
    r = rects[names[int(sys.argv[2]) % len(names)]]
    print(int((r[0] + r[2]) / 2), int((r[1] + r[3]) / 2))
PY
)
    [ -n "$at" ] || return 0
    xdotool mousemove --window "$win" $at mousedown 1 sleep 0.1 mouseup 1 2>/dev/null || true
    act="click $at"
    nclicks=$((nclicks + 1))
}
screenshot() { # the window must not be blank (all one colour or all black)
    local f="$out/shot-$nshots.png" stats
    import -window "$win" "$f" 2>/dev/null || return 0
    stats=$(convert "$f" -colorspace gray -format '%[fx:maxima] %[fx:standard_deviation]' info: 2>/dev/null || echo "0 0")
    nshots=$((nshots + 1))
    echo "$f $stats" >>"$out/screenshots.txt"
    awk -v s="$stats" 'BEGIN { split(s, a, " "); exit !(a[1] < 0.02) }' && blank=$((blank + 1))
    return 0
}

while :; do
    now=$(date +%s)
    el=$((now - start))
    [ "$el" -ge "$budget" ] && break
    kill -0 "$app" 2>/dev/null || break
    r=$(rss); [ -n "$r" ] && [ "$el" -ne "$last_rss" ] && { echo "$el,$r" >>"$out/rss.csv"; last_rss=$el; }
    [ $((el - last_check)) -ge 45 ] && { checkpoint; last_check=$el; echo "$el checkpoint" >>"$out/actions.log"; continue; }
    act=""
    case $((RANDOM % 20)) in
    0)  # resize: tiny, medium or large; then a look at the window
        case $((RANDOM % 3)) in
        0) w=$((40 + RANDOM % 160)) h=$((30 + RANDOM % 120)) ;;
        1) w=$((300 + RANDOM % 700)) h=$((200 + RANDOM % 500)) ;;
        *) w=$((1000 + RANDOM % 601)) h=$((600 + RANDOM % 401)) ;;
        esac
        xdotool windowsize "$win" "$w" "$h" 2>/dev/null || true
        act="resize ${w}x$h"
        nresizes=$((nresizes + 1))
        if [ "$w" -ge 600 ] && [ $((RANDOM % 3)) -eq 0 ]; then sleep 3; screenshot; fi ;;
    1|2) click ;;
    3)  edit_scene; sleep 0.2; xdotool key --window "$win" F5 2>/dev/null || true; act="F5 after edit $ninvalid"; nreloads=$((nreloads + 1)) ;;
    *)  k=${keys[$((RANDOM % ${#keys[@]}))]}
        read -r how name _ <<<"$k"
        # P renders a full-resolution screenshot: only now and then.
        [ "$name" = p ] && [ $((RANDOM % 3)) -ne 0 ] && continue
        if [ "$how" = hold ]; then
            xdotool keydown --window "$win" "$name" sleep "0.$((1 + RANDOM % 8))" keyup --window "$win" "$name" 2>/dev/null || true
            nholds=$((nholds + 1))
        else
            xdotool key --window "$win" "$name" 2>/dev/null || true
        fi
        act="$how $name"
        nkeys=$((nkeys + 1)) ;;
    esac
    echo "$el $act" >>"$out/actions.log"
    sleep "0.$((RANDOM % 5))"
done
# A last look at a normal-size window, then wait for --exit-after.
checkpoint; screenshot
hang=0
while kill -0 "$app" 2>/dev/null; do
    r=$(rss); el=$(($(date +%s) - start)); [ -n "$r" ] && echo "$el,$r" >>"$out/rss.csv"
    if [ "$el" -gt $((exit_after + margin)) ]; then
        hang=1
        gdb -p "$app" -batch -ex 'thread apply all bt' >"$out/hang-stacks.txt" 2>&1 || true
        kill -9 "$app"; break
    fi
    sleep 2
done
status=0; wait "$app" || status=$?
ended=$(($(date +%s) - start))
app=""
panics=$(grep -c 'panicked' "$out/stderr.txt" || true)
# The P screenshots are the rendered picture alone (no overlay): not blank,
# and the share of pure-black pixels (where a NaN would show) reported.
nrender=0
for f in "$tmp"/lensview-*.png; do
    [ -e "$f" ] || continue
    g="$out/render-$nrender.png"; cp "$f" "$g"; nrender=$((nrender + 1))
    stats=$(convert "$g" -colorspace gray -format '%[fx:maxima] %[fx:standard_deviation] %wx%h' info: 2>/dev/null || echo "0 0 ?")
    black=$(convert "$g" -colorspace gray -threshold 0 -negate -format '%[fx:mean]' info: 2>/dev/null || echo 1)
    echo "$g $stats black $black" >>"$out/screenshots.txt"
    awk -v s="$stats" 'BEGIN { split(s, a, " "); exit !(a[1] < 0.02) }' && blank=$((blank + 1))
done
python3 "$root/benches/soak_rss.py" "$out" "$root/core/src/limits.rs" >"$out/summary.txt"
cat "$out/summary.txt"
echo "seed $seed, ${minutes} min: keys $nkeys ($nholds held flight keys), resizes $nresizes, clicks $nclicks, F5 reloads $nreloads ($ninvalid of a broken file), window screenshots $nshots, P renders $nrender ($blank blank in all)"
[ -e "$out/screenshots.txt" ] && cat "$out/screenshots.txt"
echo "frames presented: $(wc -l <"$out/frames.jsonl"); frame-log lines with a null (NaN) figure: $(sed 's/"reprojection":null//' "$out/frames.jsonl" | grep -c null || true) (the log has no pixel NaN field; \`reprojection\` is null on frames that are not reprojections)"
echo "exit status $status after ${ended} s (--exit-after $exit_after, margin $margin s); hang: $hang; panics: $panics"
echo "logs in $out"
fail=0
[ "$panics" -eq 0 ] || { echo "FAIL: panic"; grep -m3 -A3 panicked "$out/stderr.txt"; fail=1; }
[ "$status" -eq 0 ] || { echo "FAIL: exit status $status"; tail -5 "$out/stderr.txt"; fail=1; }
[ "$hang" -eq 0 ] || { echo "FAIL: still running $margin s after --exit-after"; fail=1; }
[ "$blank" -eq 0 ] || { echo "FAIL: $blank blank screenshots"; fail=1; }
grep -q '^growth FAIL' "$out/summary.txt" && { echo "FAIL: RSS grew"; fail=1; }
exit $fail
