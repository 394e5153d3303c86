#!/bin/sh
# make calibrate-demo / make measure-calib (docs/calibration.md): calibrate the simulated demo
# rig (config/demo-rig.ini) from scratch, starting from the nominal file (config/sim-calib.ini);
# scan the bunny with the result; print the table parameter | true | nominal | recovered | error.
# With "measure" it also scans the bunny with the true and the nominal file, and with the true
# file less the projector's distortion, and prints each scan's distance to the true surface.
# Usage: scripts/measure-calib.sh BUILD [measure]
set -eu
build=$1
what=${2:-demo}
out=scans/calib-demo
top=$(pwd)
rm -rf "$out"
mkdir -p "$out"

# a config for scanning the demo rig with calibration file $1 into $2
scan_with() {
    sed -e "s|^calibration = .*|calibration = $1|" -e "s|^rig = .*|rig = $top/config/demo-rig.ini|" \
        -e "s|^mesh_file = ../|mesh_file = $top/|" config/calib-demo.ini > "$2.ini"
    if ! "$build/scanner" scan --config "$2.ini" --out "$2" --replace >"$2.log" 2>&1; then
        echo refused # a file far enough off that the registration refuses the views (the log says)
        return 0
    fi
    tail -n 1 "$2.log" >&2
    "$build/mesh-compare" "$2/mesh.ply" "$2/truth_mesh.ply" > "$2.compare"
    sed -n 's/^result -> truth: mean \([0-9.]*\) mm.*/\1/p' "$2.compare"
}

echo "== calibrating the demo rig (every capture kept in $out/calibration-captures)"
"$build/scanner" calibrate --config config/calib-demo.ini --out "$out/calibration.ini" > "$out/calibrate.log"
tail -n 1 "$out/calibrate.log"
echo "== scanning the bunny with the recovered calibration"
recovered=$(scan_with "$top/$out/calibration.ini" "$out/scan")
echo
"$build/measure-calib" config/demo-rig.ini config/sim-calib.ini "$out/calibration.ini"
echo
if [ "$what" = measure ]; then
    echo "== scanning the bunny with the true file, the nominal file, and the true file without"
    echo "   the projector's distortion"
    truth=$(scan_with "$top/config/demo-rig.ini" "$out/scan-true")
    nominal=$(scan_with "$top/config/sim-calib.ini" "$out/scan-nominal")
    sed 's/^distortion = -0.05, .*/distortion = 0, 0, 0, 0, 0/' config/demo-rig.ini > "$out/no-proj-distortion.ini"
    nodist=$(scan_with "$top/$out/no-proj-distortion.ini" "$out/scan-no-proj-distortion")
    # What the calibration's own error does to a model, beside what the file predicts: the true
    # file's captures processed again with the recovered file (the same frames, so only the
    # calibration differs), moved rigidly onto the true file's model (as the prediction is).
    cp -r "$out/scan-true" "$out/scan-true-recovered-src"
    cp "$out/calibration.ini" "$out/scan-true-recovered-src/calibration.ini"
    "$build/scanner" process "$out/scan-true-recovered-src" --out "$out/scan-true-recovered" \
        --replace >"$out/scan-true-recovered.log" 2>&1
    "$build/mesh-compare" --align "$out/scan-true-recovered/mesh.ply" "$out/scan-true/mesh.ply" \
        >"$out/calibration-error.compare"
    echo "predicted by the file: $(sed -n 's/^; predicted depth error //p' "$out/calibration.ini")"
    echo "measured: the same captures with the recovered and the true file, $(sed -n \
        's/^result -> truth: //p' "$out/calibration-error.compare") apart"
    rm -rf "$out/scan-true-recovered-src"
    echo
    echo "| bunny scanned with                      | result -> truth mean (mm) | vs true file |"
    echo "|-----------------------------------------|---------------------------|--------------|"
    for row in "the true file:$truth" "the recovered calibration:$recovered" \
        "the nominal file:$nominal" "the true file, projector as a pinhole:$nodist"; do
        name=${row%%:*}
        mm=${row##*:}
        ratio=$(awk -v m="$mm" -v t="$truth" 'BEGIN { if (m + 0 > 0) printf "%.2fx", m / t; else print "-" }')
        printf '| %-39s | %25s | %12s |\n' "$name" "$mm" "$ratio"
    done
else
    echo "bunny scanned with the recovered calibration: result -> truth mean $recovered mm ($out/scan)"
fi
