#!/usr/bin/env bash
# Replays every example into DIR and renders its pictures: the docs/EXAMPLES.md gallery.
#   scripts/gallery.sh DIR [DEVICE] [BIN]     DEVICE: cpu (default) or cuda; BIN: build/bin
# Each example is painted and saved; press-and-drag also grid-only (Fig. 7) and without wicking
# (the paper's load model). Each painting gets a 2:1 close-up under a raking light centred on the
# region the replay reports, and an oblique view of the whole canvas under the same light.
set -uo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:?output directory}"
dev="${2:-cpu}"
bin="${3:-$here/build/bin}"
mkdir -p "$out"
replay() {  # NAME FILE [ARGS...]
  local name="$1" file="$2"; shift 2
  local t0=$SECONDS
  timeout 1200 "$bin/wetbrush" replay "$file" --device "$dev" -q -o "$out/$name.png" \
    --save "$out/$name.ora" --stats "$out/$name.json" "$@" > "$out/$name.log" 2>&1
  echo "replay $name ($dev): exit $? in $((SECONDS - t0)) s"
}
for f in "$here"/examples/*.json "$here"/examples/*.txt; do
  replay "$(basename "${f%.*}")" "$f"
done
replay press-and-drag-grid-only "$here/examples/press-and-drag.json" --grid-only
replay press-and-drag-no-wicking "$here/examples/press-and-drag.json" \
  --set transfer.wick_rate=0 --set transfer.wick_slide=0
for st in "$out"/*.json; do
  ex="$(basename "${st%.json}")"
  [ -f "$out/$ex.ora" ] || continue
  c="$(python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['region']; print('%d,%d' % (r['x0'] + r['width'] // 2, r['y0'] + r['height'] // 2))" "$st")"
  "$bin/wetbrush" render "$out/$ex.ora" --device "$dev" --center "$c" --size 720x400 --zoom 2 \
    --light -0.8,0.35,0.5 -o "$out/$ex-detail.png" > /dev/null 2>&1
  echo "render $ex detail at $c: exit $?"
  "$bin/wetbrush" render "$out/$ex.ora" --device "$dev" --camera oblique --elevation 30 \
    --light -0.8,0.35,0.5 -o "$out/$ex-oblique.png" > /dev/null 2>&1
  echo "render $ex oblique: exit $?"
done
