#!/bin/sh
# The study of docs/accuracy.md, "A map in use for an hour": what warming motors, a new session's
# homing, another room and a handle change do to the default map, on the three simulated devices,
# with the map's thermal correction (the default) and without it (--no-thermal-correction).
#   docs/studies/session_drift.sh [autograv binary] [seed] [output folder] [exact|realtime]
# Prints one table per device; the sessions' minute-by-minute JSON and curves stay in the folder
# (the curves need a display: run under xvfb-run). About 5 minutes per device on one core.
set -eu
AUTOGRAV=${1:-build/release/demo/autograv}
SEED=${2:-1}
OUT=${3:-session-drift}
TIMING=${4:-exact}
mkdir -p "$OUT"
plot() { if [ -n "${DISPLAY:-}" ]; then echo "--plot $OUT/$1.png"; fi; }
field() {  # the map's field error now, from a report: p90 / p99 in %
  python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print('%.2f / %.2f' % (100*r['field_error_p90_rel'], 100*r['field_error_p99_rel']))" "$1"
}
housing() { python3 -c "import json,sys; print(round(json.load(open(sys.argv[1]))['hottest_housing_c'], 1))" "$1"; }
drift() {  # what the calibration saw of its motors warming
  python3 -c "
import json,sys; r=json.load(open(sys.argv[1]))
print('%d points %+.2f %% at load %.3f -> %.3f: loss %.3f +- %.3f per unit load, %.0f s' % (r['thermal_drift_points'], 100*r['thermal_drift_rel'], r['thermal_load_first'], r['thermal_load_again'], r['thermal_gain_loss_per_load'], r['thermal_gain_loss_standard_error'], r['simulated_seconds']))" "$1"
}
minutes() {  # p90 / p99 at minutes 0, 5, 10, 30 and 60 of a session report's first session
  python3 -c "
import json,sys
s=json.load(open(sys.argv[1]))['sessions'][0]['samples']
at={round(x['minute']):x for x in s}
e=at[60]
print('  '.join('%.2f / %.2f' % (100*at[m]['field_error_p90_rel'], 100*at[m]['field_error_p99_rel']) for m in (0,5,10,30,60) if m in at),
      ' | at 60: winding %.0f C, one common gain %.4f would leave %.2f / %.2f' % (e['hottest_winding_c'], e['best_scale'], 100*e['rescaled_field_error_p90_rel'], 100*e['rescaled_field_error_p99_rel']))" "$1"
}
for device in ${DEVICES:-omni omega falcon}; do
  d="sim:$device"
  run() { "$AUTOGRAV" "$@" --device "$d" --seed "$SEED" --servo-timing "$TIMING" > /dev/null; }
  run calibrate --out "$OUT/$device-off.json" --report "$OUT/$device-off-calibrate.json"
  run calibrate --thermal on --out "$OUT/$device-cold.json" --report "$OUT/$device-cold-calibrate.json"
  run calibrate --thermal on --motor-start-c 45 --out "$OUT/$device-warm.json" \
    --report "$OUT/$device-warm-calibrate.json"
  after_cold=$(housing "$OUT/$device-cold-calibrate.json")
  # Used at once: the decorator starts from the load the calibration left the motors at.
  load_after=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['thermal_load_again'])" "$OUT/$device-cold-calibrate.json")
  run session --map "$OUT/$device-cold.json" --thermal on --motor-start-c "$after_cold" --no-baseline \
    --initial-thermal-load "$load_after" --sample-s 60 --report "$OUT/$device-cold-session.json" $(plot "$device-cold-session")
  run session --map "$OUT/$device-cold.json" --thermal on --motor-start-c "$after_cold" --no-baseline \
    --sample-s 300 --no-thermal-correction --report "$OUT/$device-uncorrected-session.json"
  run session --map "$OUT/$device-cold.json" --thermal on --no-baseline \
    --sample-s 300 --report "$OUT/$device-nextday-session.json"
  run session --map "$OUT/$device-warm.json" --thermal on --motor-start-c 45 --no-baseline \
    --initial-thermal-load "$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['thermal_load_again'])" "$OUT/$device-warm-calibrate.json")" \
    --sample-s 300 --report "$OUT/$device-warm-session.json"
  run session --map "$OUT/$device-cold.json" --thermal on --session 2 --ambient-c 27 --no-baseline \
    --sample-s 300 --report "$OUT/$device-session2-27C.json"
  run session --map "$OUT/$device-cold.json" --thermal on --session 3 --ambient-c 17 --no-baseline \
    --sample-s 300 --report "$OUT/$device-session3-17C.json"
  echo "$d, seed $SEED, $TIMING timing: field p90 / p99 (%) at minutes 0, 5, 10, 30, 60 of an hour's session"
  echo "  never warming (today's default map and device):       $(field "$OUT/$device-off-calibrate.json") throughout"
  echo "  calibration with warming motors:                      $(drift "$OUT/$device-cold-calibrate.json")"
  echo "  calibrated cold, used at once (motors from $after_cold C):  $(minutes "$OUT/$device-cold-session.json")"
  echo "  the same without the thermal correction:              $(minutes "$OUT/$device-uncorrected-session.json")"
  echo "  the same map the next day, cold start at 22 C:        $(minutes "$OUT/$device-nextday-session.json")"
  echo "  calibrated warm (45 C), used at once:                 $(minutes "$OUT/$device-warm-session.json")"
  echo "  the cold map, session 2 (homed again), room 27 C:     $(minutes "$OUT/$device-session2-27C.json")"
  echo "  the cold map, session 3 (homed again), room 17 C:     $(minutes "$OUT/$device-session3-17C.json")"
done
