#!/bin/sh
# make measure-calib-sigma (issue 31): is the uncertainty a calibration reports honest? The demo
# rig is calibrated SEEDS times (default 10) from scratch, the simulator's noise drawn from
# another seed each time (config/calib-demo.ini, [sim] seed = 1 .. SEEDS); for each value, the
# spread of the results (their standard deviation over the seeds) beside the mean of the one
# standard deviation the calibrations reported. Honest: the ratio within 0.5 .. 2.
# Usage: scripts/measure-calib-sigma.sh BUILD; CONFIG=F for another procedure (e.g. fewer
# placements), SEEDS=N.
set -eu
build=$1
seeds=${SEEDS:-10}
cfg=${CONFIG:-config/calib-demo.ini}
out=$build/measure-calib-sigma
top=$(pwd)
dir=$(cd "$(dirname "$cfg")" && pwd)
rm -rf "$out"
mkdir -p "$out"
# a value of calibration file $1: section $2, key $3, field $4
value() {
    awk -v s="[$2]" -v k="$3" -v f="$4" '$0 == s { in_s = 1; next } /^\[/ { in_s = 0 }
        in_s && $1 == k { sub(/^[^=]*= */, ""); split($0, v, /, */); print v[f]; exit }' "$1"
}
# the reported 1-sigma number $2 (1-based, numbers only) of the report's line starting $1
sigma() {
    sed -n "s/^$1: 1 sigma: //p" "$3" | tr -c '0-9.e\n-' ' ' | awk -v f="$2" '{ print $f }'
}
for s in $(seq 1 "$seeds"); do
    sed -e "s|^calibration = \.\./|calibration = $top/|" -e "s|^calibration = \([^/]\)|calibration = $dir/\1|" \
        -e "s|^rig = \([^/]\)|rig = $dir/\1|" -e "s|^mesh_file = ../|mesh_file = $top/|" \
        -e "/^seed = /d" -e "s/^\[sim\]/[sim]\nseed = $s/" "$cfg" >"$out/seed-$s.ini"
    "$build/scanner" calibrate --config "$out/seed-$s.ini" --out "$out/seed-$s.cal.ini" \
        >"$out/seed-$s.log" 2>&1 || { echo "seed $s: calibration failed (see $out/seed-$s.log)"; continue; }
    r="$out/seed-$s.cal.report.txt" c="$out/seed-$s.cal.ini"
    # value and reported sigma, one row per seed: camera fx cx cy, projector fx cx cy, t1 t2 t3
    echo "$(value "$c" camera fx_px 1) $(sigma camera 1 "$r") $(value "$c" camera cx_px 1) $(sigma camera 3 "$r")" \
        "$(value "$c" camera cy_px 1) $(sigma camera 4 "$r") $(value "$c" projector fx_px 1) $(sigma projector 1 "$r")" \
        "$(value "$c" projector cx_px 1) $(sigma projector 3 "$r") $(value "$c" projector cy_px 1) $(sigma projector 4 "$r")" \
        "$(value "$c" projector translation_mm 1) $(sigma 'pose camera -> projector' 4 "$r")" \
        "$(value "$c" projector translation_mm 2) $(sigma 'pose camera -> projector' 5 "$r")" \
        "$(value "$c" projector translation_mm 3) $(sigma 'pose camera -> projector' 6 "$r")" >>"$out/rows.txt"
done
echo "| value | mean over $seeds seeds | spread (std) | reported 1 sigma (mean) | spread / reported |"
echo "|---|---|---|---|---|"
awk 'BEGIN { split("camera fx_px,camera cx_px,camera cy_px,projector fx_px,projector cx_px,projector cy_px,translation x mm,translation y mm,translation z mm", name, ",") }
    { n++; for (k = 1; k <= 9; k++) { x = $(2 * k - 1); s[k] += x; q[k] += x * x; r[k] += $(2 * k) } }
    END { for (k = 1; k <= 9; k++) { m = s[k] / n; sd = sqrt((q[k] - n * m * m) / (n - 1)); rs = r[k] / n
          printf "| %s | %.4f | %.4f | %.4f | %.2f |\n", name[k], m, sd, rs, rs > 0 ? sd / rs : 0 } }' "$out/rows.txt"
