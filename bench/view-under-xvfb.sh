#!/bin/sh
# Run: xvfb-run -a -s "-screen 0 640x480x24" bench/view-under-xvfb.sh   (needs apt-get install xvfb xdotool imagemagick)
# Drives `alhazen view` under Xvfb: key 2 (Gouraud), w (wireframe), r (ray trace), then a screenshot of the X screen.
cd "$(dirname "$0")/.."
./target/release/alhazen view scenes/glass-balls.toml --width 480 --height 360 -o /tmp/view-traced.png &
pid=$!
sleep 2
win=$(xdotool search --name "alhazen view" | head -1)
xdotool windowactivate --sync $win 2>/dev/null; xdotool windowfocus $win
xdotool key --window $win 2; sleep 0.5
xdotool key --window $win w; sleep 0.5
import -window root docs/images/view-wireframe-gouraud.png
xdotool key --window $win r; sleep 4
import -window root docs/images/view-ray-traced.png
xdotool key --window $win Escape; sleep 0.5
kill $pid 2>/dev/null
ls -la /tmp/view-traced.png docs/images/view-*.png
