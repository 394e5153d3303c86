#!/bin/sh
# make eval-texture (issue 34): the texture atlas against the vertex colours on the simulator.
# For each scene (default: the bunny wrapped in a photograph, and painted in patches) one 8-view
# scan, processed with [colour] method multi (white-referenced by scanner calibrate-white), then
# build/texture-eval: CIEDE2000 of the texture and of the vertex colours against the true albedo
# over the whole surface, edges included, and across the texture's seams. Writes
# REPORT_DIR/texture-eval.md. About 5 minutes on 2 cores.
# Usage: tools/texture_eval.sh BUILD_DIR REPORT_DIR [SCENE...]
set -eu
build=$1
report=$2
shift 2
scenes=${*:-owl-photo owl}
work=$build/eval-texture
mkdir -p "$work" "$report"
"$build/scanner" calibrate-white --config tests/eval/white.ini > "$work/white.txt"
scale=$(awk '$1 == ";" && $2 == "multi" { getline; sub(/^white_scale = /, ""); print }' "$work/white.txt")
out=$report/texture-eval.md
{
    echo "| scene | texture | texel mm | each view before fusion: mean | p95 | texture dE00 mean | p95 | vertex colours mean | p95 | dark paint: texture | vertex colours | seams mean | seams max | texture CPU s |"
    echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
} > "$out"
for scene in $scenes; do
    scan=$work/$scene
    rm -rf "$scan" "$scan-multi"
    echo "eval-texture: scanning $scene" >&2
    "$build/scanner" scan --config "tests/eval/$scene.ini" --out "$scan" > "$work/$scene.log" 2>&1
    sed -e "s/^white_scale = .*/white_scale = $scale/" -e "s|^calibration = .*|calibration = calibration.ini|" \
        "$scan/config.ini" > "$scan-multi.ini"
    "$build/scanner" process "$scan" --config "$scan-multi.ini" --out "$scan-multi" > "$scan-multi.log" 2>&1
    "$build/texture-eval" "$scan" "$scan-multi" "tests/eval/$scene.ini" > "$scan-multi.eval"
    head -n 1 "$scan-multi.eval" >&2
    size=$(sed -n 's/.*; texture \([0-9]* x [0-9]*\), .*/\1/p' "$scan-multi.log")
    texel=$(sed -n 's/.*; texture [0-9]* x [0-9]*, \([0-9.]*\) mm a texel.*/\1/p' "$scan-multi.log")
    cpu=$(sed -n 's/.*; texture .* view saw (\([0-9.]*\) s CPU).*/\1/p' "$scan-multi.log")
    awk -F, -v s="$scene" -v size="$size" -v texel="$texel" -v cpu="$cpu" '$1 == "views" {
        views = $3 " | " $4 } $1 == "csv" { row = $3 " | " $4 " | " $5 " | " $6 " | " $8 " | " $9 " | " $11 " | " $12 }
        END { printf "| %s | %s | %s | %s | %s | %s |\n", s, size, texel, views, row, cpu }' \
        "$scan-multi.eval" >> "$out"
done
cat "$out"
