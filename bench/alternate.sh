#!/usr/bin/env bash
# Two builds (or two settings) of one scene, alternated in one sitting: each run's solver time
# (GPU timestamps, else wall), then the medians and their ratio. Speed is only ever compared so.
#   bench/alternate.sh OLD_PBFLOW NEW_PBFLOW SCENE FRAMES ROUNDS [--param ... for both]
set -euo pipefail
old=$1 new=$2 scene=$3 frames=$4 rounds=$5
shift 5
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
for _ in $(seq "$rounds"); do
  for which in old new; do
    bin=$([[ $which == old ]] && echo "$old" || echo "$new")
    log=$("$bin" run "$scene" --no-render --frames "$frames" --out "$dir/$which" "$@" 2>&1)  # a directory each: builds may write different files
    echo "$which $(sed -n 's/.*(solver time \([0-9.e+-]*\) s).*/\1/p' <<<"$log")"
  done
done | tee "$dir/times" >&2
python3 - "$dir/times" "$scene" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1])]
med = {w: statistics.median(float(t) for k, t in rows if k == w) for w in ("old", "new")}
print(f"| {sys.argv[2]} | {med['old']:.2f} | {med['new']:.2f} | {med['new'] / med['old']:.3f} |")
PY
