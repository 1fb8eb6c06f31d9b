#!/usr/bin/env bash
# Hashes of everything the tools write, to show that a restructuring changes no behaviour.
# Usage: tests/output_hashes/output_hashes.sh AUTOGRAV_BINARY RESULT_DIR
# Writes every map, report and picture that demo/run.sh and `bench --friction-sweep --sweep-grid 3`
# write, on all three simulated devices, into one fixed scratch path (so that the paths written
# into reports match between runs), moves them to RESULT_DIR with their raw sha256 sums
# (sums.txt) and prints one sha256 per file after normalize_outputs.py has taken out what follows
# the wall clock, then one hash of them all. Run it with the binary before and after a change and
# compare the last line. Needs xvfb-run and python3.
set -euo pipefail
bin="$(realpath "$1")"; result="$(realpath -m "$2")"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
exec 9>/tmp/hashrun.lock; flock 9  # one run at a time: they share the scratch path
out=/tmp/hashrun/out
rm -rf /tmp/hashrun; mkdir -p "$out"; cd /tmp/hashrun
for device in sim:omni sim:omega sim:falcon; do
  name="${device#sim:}"
  "$bin" calibrate --device "$device" --grid 5 --out "$out/${name}_map.json" \
    --report "$out/${name}_calibration.json" > "$out/${name}_calibrate.stdout" 2>&1
  xvfb-run -a -s "-screen 0 1600x1200x24" "$bin" render "$out/${name}_map.json" \
    -o "$out/${name}_scene.png" --size-px 1280x960 --truth "$device" > "$out/${name}_render.stdout" 2>&1
  # A FAIL verdict exits 1: the exit code is part of the output, not the end of the run.
  "$bin" verify "$out/${name}_map.json" --device "$device" --report "$out/${name}_verify.json" \
    > "$out/${name}_verify.stdout" 2>&1 || echo "exit $?" >> "$out/${name}_verify.stdout"
  "$bin" inspect "$out/${name}_map.json" > "$out/${name}_inspect.stdout" 2>&1
done
xvfb-run -a -s "-screen 0 1600x1200x24" "$bin" bench --friction-sweep --sweep-grid 3 \
  --report "$out/sweep.json" --plot "$out/sweep.png" > "$out/sweep.stdout" 2>&1
rm -rf "$result"; mkdir -p "$(dirname "$result")"; mv "$out" "$result"
(cd "$result" && sha256sum * > sums.txt)
python3 "$here/normalize_outputs.py" "$result" | tee "$result.normalized"
echo "all outputs: $(sha256sum < "$result.normalized" | cut -d' ' -f1)"
