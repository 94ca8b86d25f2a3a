#!/usr/bin/env bash
# The README's pictures: one 1280x720 frame of each built-in scene at its defaults (fluid
# style, default camera; each at a moment that shows it: the wave up the far wall, the drop going
# in, the columns' jet, the front thrown over the box, the piston's waves, the paddle's heap, the slosh up an end wall, the cup filling, the fountain's arc, the cup poured over its rim, the blocks afloat and sunk), and an animated preview of the dam break (GIF, 480x270, 15 fps,
# its first 2 s), rendered on whatever device `auto` picks.
#   docs/images/render.sh        (from anywhere; needs build/pbflow and ffmpeg)
set -euo pipefail
cd "$(dirname "$0")/../.."
out=docs/images
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# scene and the frame shown (60 fps)
for pick in dam_break:36 drop:24 double_dam_break:30 dam_obstacle:24 hydrostatic:30 wave_tank:150 mixer:90 slosh:150 cup:60 fountain:120 pour:270 floating:180; do
  scene=${pick%:*} frame=${pick#*:}
  build/pbflow run "$scene" --frames $((frame + 1)) --quiet --out "$tmp/$scene"
  cp "$tmp/$scene/frames/frame_$(printf %05d "$frame").png" "$out/${scene}.png"
done
build/pbflow run dam_break --frames 121 --quiet --width 480 --height 270 --fluid-resolution full --out "$tmp/preview"
ffmpeg -loglevel error -y -framerate 60 -i "$tmp/preview/frames/frame_%05d.png" \
  -vf "fps=15,split[a][b];[a]palettegen=max_colors=128[p];[b][p]paletteuse=dither=bayer:bayer_scale=3" \
  "$out/dam_break_preview.gif"
ls -l "$out"/*.png "$out"/*.gif
