#!/usr/bin/env bash
# Rendering cost beside the solver's, per frame, from the same runs: every style at each
# resolution, on one scene (default dam_break, its default setting), over its first frames.
# "capture" is the whole capture stage, "drawing" its part before the PNG (particles to GL,
# draw, read back), "GPU drawing" the GL timer query's time for the draw alone; "solver" is
# the GPU time of the frame's steps (timestamps). All come
# from the run's summary, so each row's ratio is measured in one run. The fluid style runs
# once per surface size (--fluid-resolution).
#
#   bench/render.sh [-s scene] [-f frames] [-r "640x360 1280x720 1920x1080"] [-y "fluid particles"] [-q "half full"] > table.md
set -euo pipefail
cd "$(dirname "$0")/.."
scene=dam_break
frames=16
sizes="640x360 1280x720 1920x1080"
styles="fluid particles density speed"
surfaces="half full"
while getopts "s:f:r:y:q:" opt; do
  case $opt in
    s) scene=$OPTARG ;;
    f) frames=$OPTARG ;;
    r) sizes=$OPTARG ;;
    y) styles=$OPTARG ;;
    q) surfaces=$OPTARG ;;
    *) echo "usage: $0 [-s scene] [-f frames] [-r sizes] [-y styles] [-q surfaces]" >&2; exit 2 ;;
  esac
done
bin=${PBFLOW:-build/pbflow}  # PBFLOW: another build to compare
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
echo "| scene | style | surface | size | particles | solver ms/frame | capture ms/frame | drawing ms/frame | GPU drawing ms/frame | drawing / solver |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for size in $sizes; do
  for style in $styles; do
    for surface in $([[ $style == fluid ]] && echo "$surfaces" || echo -); do
      log=$("$bin" run "$scene" --frames "$frames" --style "$style" --width "${size%x*}" --height "${size#*x}" \
            $([[ $surface != - ]] && echo --fluid-resolution "$surface") --out "$dir/run" 2>&1) || { echo "$log" >&2; exit 1; }
      particles=$(sed -n 's/^particles \([0-9]*\),.*/\1/p' <<<"$log")
      solver_s=$(sed -n 's/.*(solver time \([0-9.e+-]*\) s).*/\1/p' <<<"$log")
      capture_ms=$(sed -n 's/.*(\([0-9.e+-]*\) ms per frame, .*/\1/p' <<<"$log")
      drawing_ms=$(sed -n 's/.*ms per frame, \([0-9.e+-]*\) of it drawing.*/\1/p' <<<"$log")
      gpu_ms=$(sed -n 's/.* of it drawing, \([0-9.e+-]*\) of that on the GPU).*/\1/p' <<<"$log")
      awk -v sc="$scene" -v st="$style" -v su="$surface" -v sz="$size" -v n="$particles" -v s="$solver_s" -v c="$capture_ms" \
        -v r="$drawing_ms" -v g="$gpu_ms" -v f="$frames" 'BEGIN { sm = 1000 * s / (f - 1);
        printf "| %s | %s | %s | %s | %s | %.2f | %.2f | %.2f | %.2f | %.2f |\n", sc, st, su, sz, n, sm, c, r, g, r / sm }'
    done
  done
done
