#!/bin/sh
# make measure-large (issue 33): make run's scan with a DSLR's full 4896 x 3264 frames, decoded
# and fused without binning by the LIMITS=large build, beside the same rig at 1280 x 960: the
# points a view, the model against the truth, the scan's CPU and rig time, its peak memory and
# the build's static buffers (and how much of them the live scan touched at most: the live scan's
# peak includes the simulator's rendering, which a rig has not; scripts/rss_split.py); then
# `scanner process` of the same scan, whose peak memory is the scanner's own. The
# sensor sits behind the same lens: the focal length and the principal point in pixels scale
# with the width. Writes BUILD/measure-large/; about 4 minutes
# and 5 GB of kept frames here (removed once measured; KEEP=1 keeps them).
# Usage: scripts/measure-large.sh BUILD_DIR   (the LIMITS=large build: build/large)
set -eu
build=$1
out=$build/measure-large
rm -rf "$out"
mkdir -p "$out"
static=$(size -A "$build/scanner" | awk '$1 ~ /^\.(data|bss|lbss|ldata)$/ { s += $2 }
    END { printf "%.0f", s / 1048576 }')
echo "| frames | points in view 1 | model -> truth mean mm | truth within 1 mm | scan CPU s (cost line) | rig clock s | peak resident MB, scan (simulator included; the scanner's static buffers at their peak) | peak resident MB, process | static buffers MiB |"
echo "|---|---|---|---|---|---|---|---|---|"
for size in 1280x960 4896x3264; do
    w=${size%x*} h=${size#*x}
    s=$(awk -v w="$w" 'BEGIN { printf "%.6f", w / 1280 }')
    awk -v s="$s" -v w="$w" -v h="$h" '
        /^\[/ { sec = $0 }
        sec == "[camera]" && $1 == "fx_px" { $3 = 2400 * s }
        sec == "[camera]" && $1 == "fy_px" { $3 = 2400 * s }
        sec == "[camera]" && $1 == "cx_px" { $3 = (w - 1) / 2 }
        sec == "[camera]" && $1 == "cy_px" { $3 = (h - 1) / 2 }
        sec == "[camera]" && $1 == "width" { $3 = w }
        sec == "[camera]" && $1 == "height" { $3 = h }
        { print }' config/sim-calib.ini > "$out/calib-$size.ini"
    grep -q "^fx_px = 2400$" config/sim-calib.ini # the lens this scales
    sed -e "s/^width = 1280$/width = $w/" -e "s/^height = 960$/height = $h/" \
        -e "s|^calibration = .*|calibration = $PWD/$out/calib-$size.ini|" \
        -e "s|^mesh_file = \.\./|mesh_file = $PWD/|" config/sim.ini > "$out/sim-$size.ini"
    /usr/bin/time -f "%M" -o "$out/rss-$size.txt" \
        "$build/scanner" scan --config "$out/sim-$size.ini" --out "$out/scan-$size" \
        > "$out/scan-$size.log" 2>&1 &
    timed=$!
    sleep 0.2 # time's child: the scanner, whose resident memory is split as it runs
    /usr/bin/python3 scripts/rss_split.py "$(pgrep -P "$timed" scanner || echo 0)" \
        > "$out/rss-split-$size.txt"
    wait "$timed"
    "$build/mesh-compare" "$out/scan-$size/mesh.ply" "$out/scan-$size/truth_mesh.ply" \
        > "$out/compare-$size.txt"
    points=$(sed -n 's/^view 1 of [0-9]*: \([0-9]*\) points.*/\1/p' "$out/scan-$size.log")
    mean=$(sed -n 's/^result -> truth: mean \([0-9.]*\) mm.*/\1/p' "$out/compare-$size.txt")
    within=$(sed -n 's/^truth -> result: .*within 1 mm \([0-9.]*%\).*/\1/p' "$out/compare-$size.txt")
    cpu=$(sed -n 's/^cost: the scan \([0-9.]*\) s CPU.*/\1/p' "$out/scan-$size.log")
    rig=$(sed -n 's/.*; \([0-9.]*\) s on the rig.s clock$/\1/p' "$out/scan-$size.log")
    rss=$(awk '{ printf "%.0f", $1 / 1024 }' "$out/rss-$size.txt")
    own=$(awk '{ print $2 }' "$out/rss-split-$size.txt")
    /usr/bin/time -f "%M" -o "$out/rss-process-$size.txt" \
        "$build/scanner" process "$out/scan-$size" --out "$out/processed-$size" \
        > "$out/process-$size.log" 2>&1
    cmp "$out/scan-$size/mesh.ply" "$out/processed-$size/mesh.ply" # the same scan made again
    rss_process=$(awk '{ printf "%.0f", $1 / 1024 }' "$out/rss-process-$size.txt")
    echo "| $w x $h | $points | $mean | $within | $cpu | $rig | $rss ($own) | $rss_process | $static |"
    rm -rf "$out/processed-$size"
    [ "${KEEP:-0}" = 1 ] || rm -rf "$out/scan-$size"/view_*
done
