#!/bin/sh
# make eval: Jost et al.'s colour experiments reproduced on the simulated rig. For each scene of
# tests/eval/ it takes one 8-view scan (every colour frame), processes it again with each
# [colour] method (white-referenced by scanner calibrate-white), measures the fused colour against
# the true albedo with build/colour-eval, and writes REPORT_DIR/colour-eval.csv and .md and the
# close-up PNGs. Usage: tests/colour_eval.sh BUILD_DIR REPORT_DIR [SCENE...]
set -eu
build=$1
report=$2
shift 2
scenes=${*:-owl can owl-red-plastic can-red-plastic owl-gold-metallic-paint can-gold-metallic-paint}
methods="none single uniform multi"
work=$build/eval
mkdir -p "$work" "$report"

# White reference: one view of the white sphere gives each method's white_scale.
"$build/scanner" calibrate-white --config tests/eval/white.ini > "$work/white.txt"
scale_of() { # method -> its white_scale line's value
    awk -v m="$1" '$1 == ";" && $2 == m { getline; sub(/^white_scale = /, ""); print }' \
        "$work/white.txt"
}

csv=$report/colour-eval.csv
echo "scene,method,$("$build/colour-eval" header | cut -d, -f2-)" > "$csv"
for scene in $scenes; do
    scan=$work/$scene
    rm -rf "$scan"
    echo "eval: scanning $scene" >&2
    "$build/scanner" scan --config "tests/eval/$scene.ini" --out "$scan" --json > "$work/$scene.log"
    for m in $methods; do
        cfg=$work/$scene-$m.ini
        scale=$(scale_of "$m")
        sed -e "s/^method = .*/method = $m/" -e "s/^white_scale = .*/white_scale = $scale/" \
            -e "s|^calibration = .*|calibration = calibration.ini|" "$scan/config.ini" > "$cfg"
        rm -rf "$work/$scene-$m"
        "$build/scanner" process "$scan" --config "$cfg" --out "$work/$scene-$m" --json \
            > "$work/$scene-$m.log"
        "$build/colour-eval" measure "$scan" "$work/$scene-$m" "$scene,$m" >> "$csv"
    done
    "$build/colour-eval" closeup "$scan" "$report/closeup-$scene.png" \
        $(for m in $methods; do printf '%s ' "$work/$scene-$m"; done)
done
awk -F, -f tests/colour_eval_report.awk "$csv" > "$report/colour-eval.md"
echo "eval: $report/colour-eval.md" >&2
