#!/bin/sh
# Run: xvfb-run -a -s "-screen 0 640x480x24" bench/view-under-xvfb.sh   (needs apt-get install xvfb xdotool imagemagick)
# Drives `alhazen view` under Xvfb: key 2 (Gouraud), w (wireframe), r (ray trace), then a screenshot of the X screen.
# Keys are held for 0.3 s: a tap shorter than one frame never reaches the window's key state.
cd "$(dirname "$0")/.."
./target/release/alhazen view scenes/glass-balls.toml --width 480 --height 360 -o /tmp/view-traced.png &
pid=$!
sleep 4
win=$(xdotool search --name "alhazen view" | head -1)
xdotool windowactivate --sync "$win" 2>/dev/null; xdotool windowfocus --sync "$win" 2>/dev/null
press() { xdotool keydown "$1"; sleep 0.3; xdotool keyup "$1"; sleep 1; }
press 2
press w
import -window root docs/images/view-wireframe-gouraud.png
press r
sleep 8
import -window root docs/images/view-ray-traced.png
press Escape
kill $pid 2>/dev/null
ls -la /tmp/view-traced.png docs/images/view-*.png
