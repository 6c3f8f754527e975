#!/bin/bash
# Runs the probes of a queue file, two at a time (one process each):
#   bash docs/runs/physics_settings/batch.sh docs/runs/physics_settings/queue.txt [OUTDIR]
# Each line: NAME|POLICY|PROTOCOL|AXIS|OBJECTS|LIMIT|TRIALS|OVERRIDES (space-separated KEY=VALUE and/or "disturb").
# Writes OUTDIR/NAME.json and NAME.log (OUTDIR default /tmp/ps; the committed results are probe/NAME.json.gz).
cd "$(dirname "$0")/../../.." || exit 1
OUT=${2:-/tmp/ps}
mkdir -p "$OUT"
P=docs/runs/physics_settings/probe.py
while IFS='|' read -r name spec proto axis objs lim tr ov; do
  python $P "$spec" "$proto" "$axis" "$objs" "$lim" "$tr" "$OUT/$name.json" $ov > "$OUT/$name.log" 2>&1 &
  while [ "$(jobs -r | wc -l)" -ge 2 ]; do sleep 2; done
done < "$1"
wait
