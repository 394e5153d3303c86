#!/bin/sh
# Ordinary objects scanned as a new user would (issue 30): a config with every default
# (tests/objects.ini: no [colour] method, so raw colour; no [registration] section). A flat-faced
# box in 5 views finishes with a model close to the truth (raw colour no longer refuses faces
# seen at other angles to the light); a sphere in 3 views, whose turn its shape cannot fix,
# finishes with the table's angles kept and says so. make measure-objects covers the corpus;
# these are its essentials. Prints cmocka-style lines for tests/run.sh.
set -u
cd "$(dirname "$0")/.."
bin=${BUILD:-build}/scanner
compare=${BUILD:-build}/mesh-compare
out=${BUILD:-build}/objects-test
. tests/check.sh
rm -rf "$out"
mkdir -p "$out"
# tests/objects.ini for object $1 in $2 views, into $out/$1-$2.ini
config() {
    sed -e "s/^object = .*/object = $1/" -e "s/^views = .*/views = $2/" \
        -e "s|^calibration = ../|calibration = $PWD/|" tests/objects.ini >"$out/$1-$2.ini"
}
scan() { # object, views: the scan, its log in $out/NAME.log
    config "$1" "$2"
    "$bin" scan --config "$out/$1-$2.ini" --out "$out/$1-$2" >"$out/$1-$2.log" 2>&1
}
aligned_mean() { # the model -> truth mean distance (mm), the model moved onto the truth first
    "$compare" --align "$out/$1/mesh.ply" "$out/$1/truth_mesh.ply" |
        sed -n 's/^result -> truth: mean \([0-9.]*\) mm.*/\1/p'
}
box_test() {
    scan box 5 || { tail -n 5 "$out/box-5.log"; return 1; }
    m=$(aligned_mean box-5)
    echo "box, 5 views, defaults: model -> truth mean $m mm"
    grep '^registration' "$out/box-5.log" &&
        awk -v m="$m" 'BEGIN { exit !(m != "" && m < 0.15) }'
}
check box_5_views_with_default_settings_makes_a_model box_test
sphere_test() {
    scan sphere 3 || { tail -n 5 "$out/sphere-3.log"; return 1; }
    grep '^registration' "$out/sphere-3.log" &&
        grep -q "does not fix the .*turn.*the table's angle" "$out/sphere-3.log" &&
        grep -q '^turn = table' "$out/sphere-3/view_001/registration.ini" &&
        grep -q '^turn = table' "$out/sphere-3/view_002/registration.ini" &&
        test -f "$out/sphere-3/mesh.ply"
}
check sphere_3_views_keeps_the_tables_turn_and_says_so sphere_test
check_summary "$out"
