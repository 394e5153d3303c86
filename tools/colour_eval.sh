#!/bin/sh
# make eval: Jost et al.'s colour experiments reproduced on the simulated rig. For each scene of
# tests/eval/ it takes one 8-view scan (every colour frame), processes it again with each
# [colour] method (white-referenced by scanner calibrate-white), measures the fused colour against
# the true albedo with build/colour-eval, and writes REPORT_DIR/colour-eval.csv and .md and the
# close-up PNGs. Usage: tools/colour_eval.sh BUILD_DIR REPORT_DIR [SCENE...]
set -eu
build=$1
report=$2
shift 2
scenes=${*:-owl can owl-red-plastic can-red-plastic owl-gold-metallic-paint can-gold-metallic-paint}
methods="none single uniform multi fit"
work=$build/eval
mkdir -p "$work" "$report"

# White reference: one view of the white sphere gives each method's white_scale; once more for
# each variant below, which changes what the white sphere gives.
variants="falloff=0 ca=channel ca=pixel"
with_setting() { # KEY=VALUE FILE: the config with KEY set in its first [colour] section (a
    # scan's config.ini may have a second, for what the scan chose: light_exposure_us)
    sed "0,/^\[colour\]/s//[colour]\n${1%%=*} = ${1#*=}/" "$2"
}
"$build/scanner" calibrate-white --config tests/eval/white.ini > "$work/white.txt"
for v in $variants; do
    with_setting "$v" tests/eval/white.ini > "tests/eval/.white-$v.ini"
    "$build/scanner" calibrate-white --config "tests/eval/.white-$v.ini" > "$work/white-$v.txt"
    rm -f "tests/eval/.white-$v.ini"
done
scale_of() { # method [variant] -> its white_scale line's value
    awk -v m="$1" '$1 == ";" && $2 == m { getline; sub(/^white_scale = /, ""); print }' \
        "$work/white${2:+-$2}.txt"
}
measure() { # scene method [variant]: process the scan with those settings and measure it
    name=$2${3:+/$3}
    dir=$work/$1-$2${3:+-$3}
    cfg=$dir.ini
    sed -e "s/^method = .*/method = $2/" -e "s/^white_scale = .*/white_scale = $(scale_of "$2" "${3:-}")/" \
        -e "s|^calibration = .*|calibration = calibration.ini|" "$work/$1/config.ini" > "$cfg"
    if [ -n "${3:-}" ]; then
        with_setting "$3" "$cfg" > "$cfg.tmp" && mv "$cfg.tmp" "$cfg"
    fi
    rm -rf "$dir"
    "$build/scanner" process "$work/$1" --config "$cfg" --out "$dir" --json > "$dir.log"
    "$build/colour-eval" measure "$work/$1" "$dir" "$1,$name" >> "$csv"
}

csv=$report/colour-eval.csv
echo "scene,method,$("$build/colour-eval" header | cut -d, -f2-)" > "$csv"
# Relighting: each scene's multi and fit models under a light the scan never used, against the
# simulator's truth under it (build/relight-eval); the fit's picture beside the truth.
relit=$report/relight.csv
echo "scene,method,$("$build/relight-eval" header | cut -d, -f2-)" > "$relit"
for scene in $scenes; do
    scan=$work/$scene
    rm -rf "$scan"
    echo "eval: scanning $scene" >&2
    "$build/scanner" scan --config "tests/eval/$scene.ini" --out "$scan" --json > "$work/$scene.log"
    for m in $methods; do
        measure "$scene" "$m"
    done
    # Does the inverse-square falloff help, and is Ca better fitted to the albedo (the default),
    # one per channel or per pixel?
    if [ "$scene" = owl ] || [ "$scene" = can ]; then
        for v in $variants; do
            measure "$scene" single "$v"
            measure "$scene" multi "$v"
        done
    fi
    "$build/relight-eval" "tests/eval/$scene.ini" "$scan" "$work/$scene-multi" "$scene,multi" >> "$relit"
    "$build/relight-eval" "tests/eval/$scene.ini" "$scan" "$work/$scene-fit" "$scene,fit" \
        "$report/relit-$scene.png" >> "$relit"
    if grep -q '^albedo_pattern = patches' "tests/eval/$scene.ini"; then # it has dark paint
        "$build/colour-eval" closeup-dark "$scan" "$report/closeup-dark-$scene.png" \
            "$work/$scene-none" "$work/$scene-multi" "$work/$scene-fit"
    fi
    "$build/colour-eval" closeup "$scan" "$report/closeup-$scene.png" \
        $(for m in $methods; do printf '%s ' "$work/$scene-$m"; done)
done
awk -F, -f tools/colour_eval_report.awk "$csv" "$relit" > "$report/colour-eval.md"
echo "eval: $report/colour-eval.md" >&2
