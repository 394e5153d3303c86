#!/bin/sh
# make measure-calib-sigma (issue 31): is the uncertainty a calibration reports honest? The demo
# rig is calibrated SEEDS times (default 10) from scratch, the simulator's noise drawn from
# another seed each time (config/calib-demo.ini, [sim] seed = 1 .. SEEDS); for each value, the
# spread of the results (their standard deviation over the seeds) beside the mean of the one
# standard deviation the calibrations reported. Honest: the ratio within 0.5 .. 2. Beside it the
# RMS error against the true rig ([sim] rig), which also holds what every seed shares (the
# rendering's own bias), over the same reported sigma.
# Usage: scripts/measure-calib-sigma.sh BUILD; CONFIG=F for another procedure (e.g. fewer
# placements), SEEDS=N, KEEP=1 to keep each seed's captures (half a gigabyte each) so that the
# uncertainty can be computed again from them: FROM=D computes each seed's calibration from the
# captures a KEEP=1 run left in D (D/seed-N.cal-captures; scanner calibrate --from), a minute a
# seed instead of four.
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
# the one standard deviation calibration file $1 states for word $3 on its uncertainty line
# starting "$2" (e.g. "camera fx", fx), field $4 of the numbers after the word (1-based)
sigma() {
    awk -v l=";   $2" -v w="$3" -v f="$4" 'index($0, l) == 1 {
        for (i = 1; i <= NF; i++) if ($i == w) { v = $(i + f); sub(/,$/, "", v); print v; exit } }' "$1"
}
rig=$dir/$(sed -n 's/^rig = //p' "$cfg")
truth="$(value "$rig" camera fx_px 1) $(value "$rig" camera cx_px 1) $(value "$rig" camera cy_px 1)"
truth="$truth $(value "$rig" projector fx_px 1) $(value "$rig" projector cx_px 1)"
truth="$truth $(value "$rig" projector cy_px 1) $(value "$rig" projector translation_mm 1)"
truth="$truth $(value "$rig" projector translation_mm 2) $(value "$rig" projector translation_mm 3)"
for s in $(seq 1 "$seeds"); do
    sed -e "s|^calibration = \.\./|calibration = $top/|" -e "s|^calibration = \([^/]\)|calibration = $dir/\1|" \
        -e "s|^rig = \([^/]\)|rig = $dir/\1|" -e "s|^mesh_file = ../|mesh_file = $top/|" \
        -e "/^seed = /d" -e "s/^\[sim\]/[sim]\nseed = $s/" "$cfg" >"$out/seed-$s.ini"
    from=
    [ -z "${FROM:-}" ] || from="--from $FROM/seed-$s.cal-captures"
    # shellcheck disable=SC2086 # $from is two words or none
    "$build/scanner" calibrate --config "$out/seed-$s.ini" $from --out "$out/seed-$s.cal.ini" \
        >"$out/seed-$s.log" 2>&1 || { echo "seed $s: calibration failed (see $out/seed-$s.log)"; continue; }
    c="$out/seed-$s.cal.ini"
    [ "${KEEP:-0}" = 1 ] || rm -rf "$out/seed-$s.cal-captures" # half a gigabyte a calibration
    # value and reported sigma, one row per seed: camera fx cx cy, projector fx cx cy, t1 t2 t3
    echo "$(value "$c" camera fx_px 1) $(sigma "$c" 'camera fx' fx 1) $(value "$c" camera cx_px 1)" \
        "$(sigma "$c" 'camera fx' cx 1) $(value "$c" camera cy_px 1) $(sigma "$c" 'camera fx' cy 1)" \
        "$(value "$c" projector fx_px 1) $(sigma "$c" 'projector fx' fx 1)" \
        "$(value "$c" projector cx_px 1) $(sigma "$c" 'projector fx' cx 1)" \
        "$(value "$c" projector cy_px 1) $(sigma "$c" 'projector fx' cy 1)" \
        "$(value "$c" projector translation_mm 1) $(sigma "$c" 'projector rotation' translation 1)" \
        "$(value "$c" projector translation_mm 2) $(sigma "$c" 'projector rotation' translation 2)" \
        "$(value "$c" projector translation_mm 3) $(sigma "$c" 'projector rotation' translation 3)" >>"$out/rows.txt"
done
echo "| value | true | mean over the seeds | spread (std) | reported 1 sigma (mean) | spread / reported | RMS error vs true | error / reported |"
echo "|---|---|---|---|---|---|---|---|"
awk -v truth="$truth" 'BEGIN { split("camera fx_px,camera cx_px,camera cy_px,projector fx_px,projector cx_px,projector cy_px,translation x mm,translation y mm,translation z mm", name, ",")
                               split(truth, t, " ") }
    { n++; for (k = 1; k <= 9; k++) { x = $(2 * k - 1); s[k] += x; q[k] += x * x; r[k] += $(2 * k); e[k] += (x - t[k]) ^ 2 } }
    END { for (k = 1; k <= 9; k++) { m = s[k] / n; v = (q[k] - n * m * m) / (n - 1); sd = sqrt(v > 0 ? v : 0); rs = r[k] / n; rms = sqrt(e[k] / n)
          printf "| %s | %.4f | %.4f | %.4f | %.4f | %.2f | %.4f | %.2f |\n", name[k], t[k], m, sd, rs, (rs > 0 ? sd / rs : 0), rms, (rs > 0 ? rms / rs : 0) } }' "$out/rows.txt"
