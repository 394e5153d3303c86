#!/bin/sh
# Ordinary objects scanned as a new user would (issue 30): a config with every default
# (tests/objects.ini: no [colour] method, so raw colour; no [registration] section). A flat-faced
# box in 5 views finishes with a model close to the truth (raw colour no longer refuses faces
# seen at other angles to the light); a sphere in 3 views, whose turn its shape cannot fix,
# finishes with the table's angles kept and says so; a box that slid along its faces mid-scan is
# placed by its paint, or refused when it has none. make measure-objects covers the corpus;
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
scan_ini() { # NAME: the scan of $out/NAME.ini into $out/NAME, its log in $out/NAME.log
    "$bin" scan --config "$out/$1.ini" --out "$out/$1" >"$out/$1.log" 2>&1 ||
        { tail -n 5 "$out/$1.log"; return 1; }
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
# The box put down off the table's axis, as a person puts it ([sim] object_offset_mm): in 4
# views (90 degrees apart) neighbours share only its top, whose paint, searched across the
# table, dipped 6 to 18 mm away at two or three pairs where nothing had moved; the box stood
# 30 mm off was refused ("the object slid along its faces"), 20 mm off made a model 4.1 mm from
# the truth, said moved 13 mm. A slip's two pairs line up at opposite places; these did not.
off_axis_test() {
    config box 4
    sed -e '/^\[sim\]/a object_offset_mm = 0, 30' "$out/box-4.ini" >"$out/box-off.ini"
    printf '[output]\nkeep_frames = none\n' >>"$out/box-off.ini"
    scan_ini box-off || return 1
    m=$(aligned_mean box-off)
    echo "box, 4 views, 30 mm off the axis: model -> truth mean $m mm"
    grep '^registration' "$out/box-off.log" && ! grep -q 'moved on the table' "$out/box-off.log" &&
        awk -v m="$m" 'BEGIN { exit !(m != "" && m < 0.1) }'
}
check box_off_the_axis_in_4_views_is_not_taken_for_moved off_axis_test
# name, part of data/objects, its height (mm), views: the part stood 30, 20 mm off the axis,
# scanned without frames into $out/NAME
part_off_axis() {
    config box "$4"
    sed -e "s|^object = .*|object = mesh\nmesh_file = $PWD/data/objects/$2.ply|" \
        -e "s/^object_height_mm = .*/object_height_mm = $3/" \
        -e '/^\[sim\]/a object_offset_mm = 30, 20' "$out/box-$4.ini" >"$out/$1.ini"
    printf '[output]\nkeep_frames = none\n' >>"$out/$1.ini"
    scan_ini "$1"
}
# The stepped block 30, 20 mm off the axis in 6 views: its pairs 120 -> 180 and 300 -> 0 degrees
# share only its steps' tops, which see no turn, so the views fall into two arcs the pairs cannot
# turn against each other; the depth's bias turned the second 0.58 degrees (0.123 mm from the
# truth, 0.067 centred). Now the table's angles hold between the arcs, said.
arcs_test() {
    part_off_axis steps-off stepped_block 60 6 || return 1
    m=$(aligned_mean steps-off)
    echo "stepped block, 6 views, 30, 20 mm off the axis: model -> truth mean $m mm"
    grep -o 'cut the views into 2 arcs.*' "$out/steps-off.log" &&
        grep -q '^arcs_held = 1' "$out/steps-off/view_003/registration.ini" &&
        awk -v m="$m" 'BEGIN { exit !(m != "" && m < 0.09) }'
}
check stepped_block_off_the_axis_keeps_the_table_between_blind_pairs arcs_test
# The L-bracket 30, 20 mm off the axis in 4 views: view 2 shares with its neighbours only 200
# samples (213 mm^2 of surface), whose depth bias the pairs fitted by turning it 3.1 degrees from
# the exact table; refused then only because that passed max_correction_deg (and with the axis
# held closer, at 2.6 degrees, taken: the model 0.303 mm from the truth). Now a turn the pairs
# see over too little surface to outweigh the table keeps the table's angle, said.
bracket_test() {
    part_off_axis bracket-off l_bracket 70 4 || return 1
    m=$(aligned_mean bracket-off)
    echo "L-bracket, 4 views, 30, 20 mm off the axis: model -> truth mean $m mm"
    grep '^registration' "$out/bracket-off.log" &&
        grep -q "1 of 3 share too little surface with their neighbours" "$out/bracket-off.log" &&
        grep -q '^turn = table (too little surface' "$out/bracket-off/view_002/registration.ini" &&
        grep -q '^turns_little_shared = 1$' "$out/bracket-off/view_002/registration.ini" &&
        awk -v m="$m" 'BEGIN { exit !(m != "" && m < 0.12) }'
}
check l_bracket_off_the_axis_keeps_the_table_where_little_surface_is_shared bracket_test
# A dark object (the bunny at albedo 0.04: black plastic) at every default: every view came out
# almost empty (0 to 98 points), and after the last the registration failed naming the
# calibration. Now the exposure check before the first view finds most of what the projector
# lights too dark and takes every pattern at a longer exposure too (HDR), says so and keeps it
# in the scan's config.ini; processed again, with that file or with the person's own (which sets
# no exposures_us), the same model. Before: the scan failed, and processing with the person's
# file was refused as other settings.
dark_auto_test() {
    config mesh 2
    sed -e "/^object = mesh/a mesh_file = $PWD/data/bunny/bun_zipper.ply" \
        -e 's/^albedo_pattern = .*/albedo_pattern = uniform\nalbedo = 0.04, 0.04, 0.04/' \
        "$out/mesh-2.ini" >"$out/dark-auto.ini"
    scan_ini dark-auto || return 1
    grep -o 'info: a dark object: .*' "$out/dark-auto.log" || return 1
    long=$(sed -n 's/^exposures_us = 10000, \([0-9]*\)$/\1/p' "$out/dark-auto/config.ini")
    points=$(sed -n 's/^view 1 of 2: \([0-9]*\) points.*/\1/p' "$out/dark-auto.log")
    m=$(aligned_mean dark-auto)
    echo "every default: exposures 10000, $long us; $points points in view 1; model -> truth $m mm"
    [ "${long:-0}" -gt 10000 ] && [ "${points:-0}" -gt 50000 ] &&
        ! grep -q 'too dark to decode against' "$out/dark-auto.log" &&
        awk -v m="$m" 'BEGIN { exit !(m != "" && m < 0.1) }' || return 1
    "$bin" process "$out/dark-auto" --out "$out/dark-again" --config "$out/dark-auto.ini" \
        >"$out/dark-again.log" 2>&1 || { tail -n 3 "$out/dark-again.log"; return 1; }
    cmp "$out/dark-auto/mesh.ply" "$out/dark-again/mesh.ply" &&
        grep -q "^exposures_us = 10000, $long$" "$out/dark-again/config.ini" || return 1
    rm -rf "$out/dark-again"
    "$bin" process "$out/dark-auto" --out "$out/dark-again" >/dev/null 2>&1 &&
        cmp "$out/dark-auto/mesh.ply" "$out/dark-again/mesh.ply"
}
check dark_object_at_every_default_is_scanned_at_a_longer_exposure dark_auto_test
# The same with [scan] auto_exposure = 0: the first view says it is too dark and what exposure
# lifts it (and so does processing the scan again); the scan taken at that exposure makes its
# views.
dark_test() {
    sed '/^\[scan\]/a auto_exposure = 0' "$out/dark-auto.ini" >"$out/mesh-2.ini"
    printf '[output]\nkeep_frames = none\n' >>"$out/mesh-2.ini"
    "$bin" scan --config "$out/mesh-2.ini" --out "$out/dark" >"$out/dark.log" 2>&1 && return 1
    grep -o 'warning: view 1: .* too dark to decode.*' "$out/dark.log" || return 1
    grep -q 'error: registration failed: .*too dark to decode at exposure_us = 10000' "$out/dark.log" ||
        return 1
    # processed again from its range images alone (no frames kept), it says so too
    "$bin" process "$out/dark" >"$out/dark-process.log" 2>&1 && return 1
    grep -o 'warning: view 1: .* too dark to decode against .*longer \[camera\] exposure_us than 10000.*' \
        "$out/dark-process.log" &&
        grep -q 'error: registration failed: .*too dark to decode' "$out/dark-process.log" || return 1
    # its range images damaged (a reason byte beyond the codes, a FIFO where one belongs): one
    # error naming the file, before any view is counted, and no hang
    cp -r "$out/dark" "$out/dark-bad"
    printf '\377' | dd of="$out/dark-bad/view_000/range.bin" bs=1 seek=32 conv=notrunc 2>/dev/null
    timeout 60 "$bin" process "$out/dark-bad" >"$out/dark-bad.log" 2>&1 && return 1
    grep -q 'error: .*dark-bad/view_000/range.bin: cut short or damaged' "$out/dark-bad.log" &&
        ! grep -q 'too dark' "$out/dark-bad.log" || return 1
    cp "$out/dark/view_000/range.bin" "$out/dark-bad/view_000/range.bin"
    rm "$out/dark-bad/view_001/range.bin" && mkfifo "$out/dark-bad/view_001/range.bin"
    timeout 60 "$bin" process "$out/dark-bad" >"$out/dark-bad.log" 2>&1 && return 1
    grep -q 'error: .*dark-bad/view_001/range.bin: not a range image' "$out/dark-bad.log" || return 1
    # two bytes after its last point, less than a point (read in whole points, they went unsaid)
    rm "$out/dark-bad/view_001/range.bin" && cp "$out/dark/view_001/range.bin" "$out/dark-bad/view_001/"
    printf 'xx' >>"$out/dark-bad/view_000/range.bin"
    timeout 60 "$bin" process "$out/dark-bad" >"$out/dark-bad.log" 2>&1 && return 1
    grep -q 'error: .*dark-bad/view_000/range.bin: cut short or damaged' "$out/dark-bad.log" || return 1
    want=$(sed -n 's/.*raise \[camera\] exposure_us from 10000 to about \([0-9]*\).*/\1/p' "$out/dark.log")
    [ -n "$want" ] && [ "$want" -gt 10000 ] || return 1
    # kept with its frames, processing says the same exposure
    sed '/^keep_frames = none/d' "$out/mesh-2.ini" >"$out/dark-frames.ini"
    scan_ini dark-frames && return 1
    "$bin" process "$out/dark-frames" >"$out/dark-frames-process.log" 2>&1 && return 1
    grep -o "warning: view 1: .*To scan it again, raise \[camera\] exposure_us from 10000 to about $want .*" \
        "$out/dark-frames-process.log" || return 1
    sed "s/^exposure_us = .*/exposure_us = $want/" "$out/mesh-2.ini" >"$out/dark-lit.ini"
    scan_ini dark-lit || return 1
    points=$(sed -n 's/^view 1 of 2: \([0-9]*\) points.*/\1/p' "$out/dark-lit.log")
    echo "at exposure_us = $want: $points points in view 1"
    ! grep -q 'too dark' "$out/dark-lit.log" && [ "${points:-0}" -gt 50000 ]
}
check dark_object_is_said_with_the_exposure_that_lifts_it dark_test
sphere_test() {
    scan sphere 3 || { tail -n 5 "$out/sphere-3.log"; return 1; }
    grep '^registration' "$out/sphere-3.log" &&
        grep -q "does not fix the .*turn.*the table's angle" "$out/sphere-3.log" &&
        grep -q '^turn = table' "$out/sphere-3/view_001/registration.ini" &&
        grep -q '^turn = table' "$out/sphere-3/view_002/registration.ini" &&
        test -f "$out/sphere-3/mesh.ply"
}
check sphere_3_views_keeps_the_tables_turn_and_says_so sphere_test
# A small object (the box 5 mm tall: about 200 points a view at 1280 x 960) in 4 views: too
# few samples to register, it failed ("view 1 does not match view 0 ... is the calibration not
# this rig's?") and made no model; now the table's angles are kept and the model made, said so.
small_test() {
    config box 4
    sed -e 's/^object_height_mm = .*/object_height_mm = 5/' "$out/box-4.ini" >"$out/small.ini"
    printf '[output]\nkeep_frames = none\n' >>"$out/small.ini"
    scan_ini small || return 1
    grep '^registration' "$out/small.log" | grep -q 'too few points to register.*small in the camera' &&
        ! grep -q 'error' "$out/small.log" && test -s "$out/small/mesh.ply" || return 1
    # in two passes the second cannot be found in the first: said so, not "was it the same object?"
    sed -e 's/^views = 4/views = 4\npasses = 2/' "$out/small.ini" >"$out/small-2.ini"
    scan_ini small-2 >/dev/null && return 1
    grep -q 'error: registration failed: the second pass (from view 4) cannot be found in the first: the views hold too few points' \
        "$out/small-2.log"
}
check small_object_keeps_the_tables_angles_and_says_so small_test
# Few lights (2026-12-08): the bunny in 4 views coloured with one light (multi) and with two
# (uniform). Where no light reaches a pixel has no colour, and a surface lit in one view is
# shadowed in the next; uniform's colour is shaded by the lights as they fall. Both failed their
# registration ("1% of their overlap couples ... is the calibration not this rig's?"): the
# uncoloured side was taken for black paint, uniform's shading compared as the paint's. The
# table ends its moves up to 1 degree off, so that the registration has turns to correct.
few_lights_test() {
    for case in "multi 1" "uniform 2"; do
        set -- $case
        config mesh 4
        sed -e "/^object = mesh/a mesh_file = $PWD/data/bunny/bun_zipper.ply" \
            -e "s/^count = .*/count = $2/" -e "/^seed = /a table_angle_error_mdeg = 1000" \
            "$out/mesh-4.ini" >"$out/lights-$1.ini"
        printf '[colour]\nmethod = %s\n[output]\nkeep_frames = none\n' "$1" >>"$out/lights-$1.ini"
        scan_ini "lights-$1" || return 1
        grep "^registration" "$out/lights-$1.log" | grep -q "the views' angles corrected" ||
            return 1
        echo "$2 light(s), $1: $(grep -o "residual [0-9.]* mm" "$out/lights-$1.log")"
    done
    # one light leaves a third of the bunny lit in no view that sees it: said, with the remedy
    grep -o "warning: [0-9]*% of the model ([0-9]* vertices) was lit by no light in any view.*count = 1).*" \
        "$out/lights-multi.log"
}
check one_or_two_lights_register few_lights_test
# Two views half a turn apart (front and back): they share no surface, which is no failure: the
# table's angles, a model, and the scan says why (it refused the pair: 0% of nothing coupled).
two_views_test() {
    config mesh 2
    sed -i "/^object = mesh/a mesh_file = $PWD/data/bunny/bun_zipper.ply" "$out/mesh-2.ini"
    "$bin" scan --config "$out/mesh-2.ini" --out "$out/bunny-2" >"$out/bunny-2.log" 2>&1 ||
        { tail -n 5 "$out/bunny-2.log"; return 1; }
    grep '^registration' "$out/bunny-2.log" &&
        grep -q "views 0 and 1 share no surface to register" "$out/bunny-2.log" &&
        grep -q '^turn = table' "$out/bunny-2/view_001/registration.ini" &&
        test -f "$out/bunny-2/mesh.ply"
}
check two_views_half_a_turn_apart_make_a_model two_views_test
# The box knocked 6 mm along one face's normal between views 3 and 4 of 8: across the break the
# views share two parallel faces and the top, which hold no slide along the faces; its paint
# does. Painted in patches, the moved views are placed by shape and colour and the model is
# whole; in one colour nothing tells how far it slid, and the scan says so, views kept.
slip_config() { # pattern [mm]: the box in 8 views, slipped (6 mm), into $out/slip-PATTERN.ini
    config box 8
    sed -e "s/^albedo_pattern = .*/albedo_pattern = $1/" \
        -e "/^\[sim\]/a slip_mm = ${2:-6}, 0, 0\nslip_at_deg = 170" "$out/box-8.ini" >"$out/slip-$1.ini"
}
slip_painted_test() {
    slip_config patches
    scan_ini slip-patches || return 1
    m=$(aligned_mean slip-patches)
    echo "box, 8 views, 6 mm slip at view 4, painted: model -> truth mean $m mm"
    grep -o 'the object moved on the table at view 4: 4 views placed by .*' "$out/slip-patches.log" &&
        grep -q "placed by the object's shape and colour" "$out/slip-patches.log" &&
        grep -q '^moved_placed_by = shape and colour' "$out/slip-patches/view_005/registration.ini" &&
        grep -q '^placed_freely = 1' "$out/slip-patches/view_005/registration.ini" &&
        grep -q '^placed_freely = 0' "$out/slip-patches/view_002/registration.ini" &&
        awk -v m="$m" 'BEGIN { exit !(m != "" && m < 0.2) }'
}
check box_slipped_along_its_faces_is_placed_by_its_paint slip_painted_test
# The box of data/objects (60 x 40 x 80 mm) pushed 30 mm: the views after the push are placed by
# their paint to within a tenth of a millimetre: each sample's hue is the mean of its pixels' (the hue of their mean colour leaned
# towards the brighter paint by how obliquely a view saw it, and placed them 0.43 mm off: the
# model 0.122 mm from the truth against 0.050 unmoved), and the hues move only the slide the
# shape leaves (on every motion they turned the views 0.3 degrees): 0.064 mm. The hues of every
# second cell only (every second column of the image) placed them 0.1 mm off along the faces;
# with every cell's, 0.055: within the issue's 1.2 times the unmoved box.
part_config() { # name, part of data/objects, its height (mm), [views6], [mm]: into $out/NAME.ini
    slip_config patches "${5:-30}"
    sed -e "s|^object = .*|object = mesh\nmesh_file = $PWD/data/objects/$2.ply|" \
        -e "s/^object_height_mm = .*/object_height_mm = $3/" "$out/slip-patches.ini" >"$out/$1.ini"
    [ "${4:-}" != views6 ] || sed -i 's/^views = .*/views = 6/' "$out/$1.ini"
}
part_pushed() { # name, part of data/objects, its height (mm), [views6], [mm]: painted, 8 (6) views, pushed 30 (mm) mm
    part_config "$@" && scan_ini "$1"
}
# KEY of scan NAME's view VIEW's registration.ini, printed as "KEY = value" too: the value
reg_value() {
    v=$(sed -n "s/^$3 = //p" "$out/$1/view_$2/registration.ini")
    echo "$3 = $v" >&2
    echo "$v"
}
# a part pushed (part_pushed's name, part, height, views6 or "", mm), placed: its log says $6
# and the model is less than $7 mm from the truth; $8 says what it is
placed_within() {
    part_pushed "$1" "$2" "$3" "$4" "$5" || return 1
    placed_check "$1" "$6" "$7" "$8"
}
# scan $1 placed: its log says $2 and the model is less than $3 mm from the truth; $4 says what it is
placed_check() {
    m=$(aligned_mean "$1")
    echo "$4: model -> truth mean $m mm"
    grep -q "$2" "$out/$1.log" && awk -v m="$m" -v x="$3" 'BEGIN { exit !(m != "" && m < x) }'
}
slip_far_test() {
    placed_within slip-far box 80 "" 30 "placed by the object's shape and colour" 0.06 \
        "box, 8 views, 30 mm slip at view 4, painted"
}
check box_pushed_30mm_is_placed_by_its_paint_within_1_2_times_unmoved slip_far_test
# The same box pushed 6 mm the other way, along the faces the pairs across the push share: in 8
# views each neighbour shares one face and the top, and a push along that face moves no residual;
# only a pair sharing a top alone was searched for a slip its paint shows, so the model came out
# 1.84 mm from the truth without a word (3 mm: 0.90; the plate with holes: 0.92). Now a pair whose
# normals all hold one way is searched along the other: placed, 0.050 mm (0.050 unmoved). Its
# paint alone places it along the push: since the simulator takes the paint over each pixel
# (2026-12-06) 0.08 mm off that way (0.059 mm from the truth), so the move is said as 6.1 mm,
# and a tenth of a millimetre either way is taken.
slip_along_test() {
    slip_config patches
    sed -e 's/^slip_mm = .*/slip_mm = 0, 6, 0/' "$out/slip-patches.ini" >"$out/slip-along.ini"
    scan_ini slip-along || return 1
    placed_check slip-along \
        "moved on the table at view 4: 4 views placed by the object's shape and colour.*as it had moved \(5\.9\|6\.0\|6\.1\) mm" \
        0.06 "box, 8 views, 6 mm slip along the shared faces at view 4"
}
check box_slipped_along_the_faces_its_neighbours_share_is_placed slip_along_test
# A hex nut in 6 views: its six-fold symmetry is the table's 60-degree step, so each view looks
# like its neighbour as they stand, and the pairs fit the table's turn about the nut's own axis
# as measured, which the depth's small bias (the same in every view) moves: the axis went 0.27 mm
# and 0.09 deg off and the model came out 0.21 mm from the truth (0.066 with the calibrated
# axis), without a word. Now the calibrated axis is kept and the line says why.
nut_six_test() {
    config box 6
    sed -e "s|^object = .*|object = mesh\nmesh_file = $PWD/data/objects/hex_nut.ply|" \
        -e "s/^object_height_mm = .*/object_height_mm = 30/" "$out/box-6.ini" >"$out/nut-6.ini"
    printf '[output]\nkeep_frames = none\n' >>"$out/nut-6.ini"
    scan_ini nut-6 || return 1
    m=$(aligned_mean nut-6)
    echo "hex nut, 6 views: model -> truth mean $m mm"
    grep -o "each view looks like its neighbour as they stand.*" "$out/nut-6.log" &&
        grep -q "axis moved 0.00 mm, tilted 0.000 deg" "$out/nut-6.log" &&
        awk -v m="$m" 'BEGIN { exit !(m != "" && m < 0.1) }'
}
check hex_nut_in_six_views_keeps_the_calibrated_axis nut_six_test
# The same nut slipped 6 mm in 6 views: the views after the slip no longer look alike (the nut
# stands off the axis), so the rule above was not taken, the pairs before the slip placed the axis
# (0.17 mm off) and the model came out 0.101 mm from the truth (0.066 unslipped). Now the views
# the table's axis is registered in (those before the slip) are judged: 0.065.
nut_slip_six_test() {
    placed_within nut-slip6 hex_nut 30 views6 6 \
        "each view before the object moved looks like its neighbour.*moved on the table at view 3: 3 views placed" \
        0.08 "hex nut, 6 views, 6 mm slip at view 3"
}
check hex_nut_slipped_in_six_views_keeps_the_calibrated_axis nut_slip_six_test
# The plate with holes of data/objects (100 x 70 x 10 mm, lying flat) pushed 30 mm: its shape
# holds neither shift along the table (its top and its holes' few walls), its paint holds both.
# The paint lined up at 0.17 of a full miss before the refinement turned it the last tenth of a
# degree, which a bound on that alone (0.14) took for a wrong place and refused the scan; now
# the placed views' colours, refined, are held to the agreement of the views of one arc (0.073
# both). The model 0.049 mm from the truth, the same plate unmoved 0.047.
slip_plate_test() {
    part_pushed slip-plate plate_holes 10 || return 1
    m=$(aligned_mean slip-plate)
    moved=$(sed -n "s/.*placed by the object's shape and colour.*as it had moved \([0-9.]*\) mm.*/\1/p" "$out/slip-plate.log")
    echo "plate with holes, 8 views, 30 mm slip at view 4: moved $moved mm said, model -> truth mean $m mm"
    grep -q "its shape alone lets them slide two ways" "$out/slip-plate.log" &&
        awk -v m="$m" -v d="$moved" 'BEGIN { exit !(m != "" && m < 0.06 && d != "" && d > 29 && d < 31) }'
}
check plate_pushed_30mm_is_placed_by_its_paint slip_plate_test
# The stepped block slipped 6 mm in 6 views: only the closing pair (the last view and the first)
# is seen to break; the pair the slip happened across couples in shape, its paint missing 2.1
# times the ring's median pair. The scan was refused, naming view 0, though 12 views of it were
# placed; now that pair is taken as the slip's other break and the views after it are placed
# (the model 0.078 mm from the truth, 0.067 unslipped).
steps_slip_six_test() {
    placed_within steps-slip6 stepped_block 60 views6 6 \
        "moved on the table at view 3: 3 views placed by the object's shape" 0.09 \
        "stepped block, 6 views, 6 mm slip at view 3"
}
check stepped_block_slipped_in_six_views_is_placed steps_slip_six_test
# The thin box (120 x 20 x 15 mm, lying flat) slipped 6 mm along its length in 6 views: the two
# pairs across the slip see only its top, which slides into itself, and their paint misses less
# than the bound a miss is judged by (0.18 of a full miss, the other pairs 0.08 to 0.14); the
# model came out 0.316 mm from the truth without a word. Their paint lines up best 6 mm away, the
# unmoved pairs' where they stand: now those two are the slip's breaks and the views after it
# are placed (0.065 mm, the same as unslipped).
thin_slip_six_test() {
    placed_within thin-slip6 thin_box 15 views6 6 \
        "moved on the table at view 3: 3 views placed by the object's shape and colour" 0.09 \
        "thin box, 6 views, 6 mm slip at view 3" || return 1
    # the views kept at the table's angle are counted once, though the registration solves again
    # for the views the object moved for (it said 2 where one view, end on, kept it)
    kept=$(cat "$out"/thin-slip6/view_*/registration.ini | grep -c '^turn = table')
    echo "views kept at the table's angle: $kept; $(grep '^turns_from_table' "$out/thin-slip6/view_000/registration.ini")"
    [ "$kept" -gt 0 ] && grep -q "^turns_from_table = $kept\$" "$out/thin-slip6/view_000/registration.ini"
}
check thin_box_slipped_in_six_views_is_placed thin_slip_six_test
# The same thin box slipped 6 mm along its length in 8 views: across the slip its views share the
# top and the two small ends, which see 0.5 % of a turn about the table's axis (reg_place.c); the
# shape lets it slide one way, the paint placed that, and ICP left a turn of 0.3 degrees from
# noise (0.3 mm at its ends; the model 0.083 mm from the truth, 0.069 unslipped). Now the paint
# holds the turn too: 0.1 degrees, 0.071 mm.
thin_slip_eight_test() {
    placed_within thin-slip8 thin_box 15 "" 6 \
        "moved on the table at view 4: 4 views placed by the object's shape and colour" 0.08 \
        "thin box, 8 views, 6 mm slip at view 4" || return 1
    turned=$(reg_value thin-slip8 005 moved_deg)
    awk -v t="$turned" 'BEGIN { exit !(t != "" && t < 0.2) }'
}
check thin_box_slipped_along_its_length_keeps_its_turn_by_its_paint thin_slip_eight_test
# The same thin box slipped 30 mm in 8 views: nothing but its paint holds it across its length,
# and the placed views came out 0.24 mm off that way (the model 1.32 times its unmoved scan's
# 0.059 mm from the truth) until the simulator took the paint over each pixel and the placed
# views' hues were read as the other arc's views see them alike (2026-12-06, reg_place.c
# add_hues_alike): 0.065 mm, within issue 30's 1.2 times.
thin_slip_far_test() {
    placed_within thin-slip30 thin_box 15 "" 30 \
        "moved on the table at view 4: 4 views placed by the object's shape and colour" \
        "$(awk 'BEGIN { print 1.2 * 0.059 }')" "thin box, 8 views, 30 mm slip at view 4"
}
check thin_box_slipped_30mm_is_placed_within_1_2_times_unmoved thin_slip_far_test
# The thin box in 8 views, the table 2 degrees off (issue 30: within 1.15 times the exact table's
# scan). The view that sees it end on kept the table's angle (its shape does not fix its turn),
# 0.6 degrees off, and the pairs moved the axis 0.09 mm from the calibrated one on their depth
# bias alone: 0.086 mm from the truth against 0.069 with the table exact, 1.25 times. Now the
# paint turns that view to where it agrees with its neighbours', and the axis stays as calibrated
# where moving it gains no more than the pairs' own errors explain: 0.060 and 0.060.
thin_table_test() {
    for t in 0 2000; do
        part_config "thin-table$t" thin_box 15 "" 0
        sed -i -e '/^slip_mm = /d' -e '/^slip_at_deg = /d'             -e "/^\[sim\]/a table_angle_error_mdeg = $t" "$out/thin-table$t.ini"
        printf '[output]\nkeep_frames = none\n' >>"$out/thin-table$t.ini"
        scan_ini "thin-table$t" || return 1
    done
    exact=$(aligned_mean thin-table0) off=$(aligned_mean thin-table2000)
    echo "thin box, 8 views: model -> truth mean $exact mm, the table 2 deg off $off mm"
    grep '^registration' "$out/thin-table2000.log" &&
        grep -q "turned from it to where the paint agrees" "$out/thin-table2000.log" &&
        grep -q "the calibrated axis kept: moving it fitted" "$out/thin-table2000.log" &&
        grep -q '^turn = paint (the shape does not fix it)' \
            "$out/thin-table2000/view_004/registration.ini" &&
        awk -v e="$exact" -v o="$off" 'BEGIN { exit !(e != "" && o != "" && o <= 1.15 * e) }'
}
check thin_box_with_the_table_2_degrees_off_within_1_15_times_exact thin_table_test
# The thin box slipped 6 mm along its length at 100 degrees in 7 views: only the closing pair
# broke in shape, the pair across the slip missed in paint 2.0 times the ring's median, just
# under what picks it, and the scan was refused. Its paint lines up 6 mm away, and no other
# pair's does: placed (0.062 mm from the truth).
thin_slip_seven_test() {
    part_config thin-slip7 thin_box 15 "" 6
    sed -i -e "s/^views = .*/views = 7/" -e "s/^slip_at_deg = .*/slip_at_deg = 100/" "$out/thin-slip7.ini"
    scan_ini thin-slip7 || return 1
    placed_check thin-slip7 "moved on the table at view 2: 5 views placed by the object's shape and colour" \
        0.08 "thin box, 7 views, 6 mm slip at 100 degrees"
}
check thin_box_slipped_early_in_seven_views_is_placed thin_slip_seven_test
# The plate pushed 30 mm in 6 views: across the push its views share the top and little else,
# which holds neither its shifts along the table nor its turn about the axis; ICP left a turn of
# 1.7 deg from noise, the paint's search moves shifts only, and the model came out 0.257 mm from
# the truth. Now the turn is taken off before the search and held through its refinement: 0.066
# (0.070 unmoved).
plate_six_test() {
    part_pushed plate-six plate_holes 10 views6 || return 1
    m=$(aligned_mean plate-six)
    turned=$(sed -n "s/.*as it had moved [0-9.]* mm and turned \([0-9.]*\) deg.*/\1/p" "$out/plate-six.log")
    echo "plate with holes, 6 views, 30 mm slip at view 3: turned $turned deg said, model -> truth mean $m mm"
    awk -v m="$m" -v t="$turned" 'BEGIN { exit !(m != "" && m < 0.09 && t != "" && t < 0.5) }'
}
check plate_pushed_in_six_views_keeps_the_tables_turn plate_six_test
# The same box pushed 30 mm in 6 views: the pairs across the push see the faces it slid along
# and couple (91% of their overlap); only the paint shows the slide. The scan once finished with
# a model 3.9 mm from the truth and no word; then it found the two pairs whose paint misses (0.99
# of a full miss, the others under 0.1) and placed the views after the push by their paint (the
# model 0.087 mm from the truth, unmoved 0.067), or said it could not. Since the simulator takes
# the paint over each pixel and the placed views' hues are read as the other arc's views see
# them alike (2026-12-06, reg_place.c add_hues_alike), it is placed within issue 30's 1.2 times
# the unmoved box in 6 views (0.064 mm, unmoved 0.065; refused before).
slip_six_test() {
    placed_within slip-six box 80 views6 30 "moved on the table at view 3: 3 views placed" \
        "$(awk 'BEGIN { print 1.2 * 0.065 }')" "box, 6 views, 30 mm slip at view 3"
}
check box_pushed_30mm_in_six_views_is_placed_within_1_2_times_unmoved slip_six_test
# The stepped block pushed 30 mm in 6 views: the views across the push land beside each other's
# surfaces, two pairs that share nothing where every other pair couples; it finished 3.0 mm
# from the truth without a word, then was cut there and refused, naming view 3: ICP from the
# table's place slid 18 mm along its top and stopped where its steps did not fit, and the search
# without a starting pose placed it turned half a turn. Now its paint, searched across the table
# from the table's place, finds the push (30.0 mm) and the shape fits there: placed, 0.070 mm
# from the truth (0.067 unpushed). With the hues of every cell (reg_place.c) it says 30.074 mm,
# the model 0.069 mm from the truth: the placement within a tenth of a millimetre of the push.
steps_six_test() {
    placed_within steps-six stepped_block 60 views6 30 \
        "moved on the table at view 3: 3 views placed by the object's shape and colour" \
        0.09 "stepped block, 6 views, 30 mm push at view 3" || return 1
    moved=$(reg_value steps-six 003 moved_mm)
    awk -v m="$moved" 'BEGIN { exit !(m != "" && m > 29.9 && m < 30.1) }'
}
check stepped_block_pushed_in_six_views_is_placed_by_its_paint steps_six_test
slip_plain_test() {
    slip_config uniform
    if "$bin" scan --config "$out/slip-uniform.ini" --out "$out/slip-uniform" >"$out/slip-uniform.log" 2>&1; then
        echo "a plain box that slid along its faces was placed anyway"
        return 1
    fi
    grep -o 'error: registration failed: the object moved on the table at view 4, .*' "$out/slip-uniform.log" &&
        grep -q "neither the object's shape .* nor its colour fixes" "$out/slip-uniform.log" &&
        test -f "$out/slip-uniform/view_007/view.ini" && test ! -f "$out/slip-uniform/mesh.ply"
}
check plain_box_slipped_along_its_faces_is_refused_naming_the_view slip_plain_test
# A cylinder 290 mm tall with every default (issue 30: it came out cut at the volume's 165 mm and
# at the image's top, without a word): the volume grows to hold what the views saw (fit_volume),
# said; the image's top, which no volume brings back, is said at its first view and at the end,
# in warnings.txt and the report too.
tall_test() {
    config cylinder 2
    sed -e "s/^object_height_mm = .*/object_height_mm = 290/" "$out/cylinder-2.ini" >"$out/tall.ini"
    printf '[output]\nkeep_frames = none\n' >>"$out/tall.ini"
    "$bin" scan --config "$out/tall.ini" --out "$out/tall" >"$out/tall.log" 2>&1 || return 1
    grep warning "$out/tall.log"
    grep -q "warning: view 1: the object runs off the camera's image" "$out/tall.log" &&
        grep -q "warning: the object runs off the camera's image in 2 of 2 views" "$out/tall.log" &&
        grep -q 'info: the fused volume grown to hold the object (\[fusion\] fit_volume): top_mm 165 -> 2[0-9][0-9].[0-9] (it reaches 2[0-9][0-9] mm up)$' \
            "$out/tall.log" && ! grep -q 'fused volume:' "$out/tall.log" &&
        test "$(wc -l <"$out/tall/warnings.txt")" -eq 1 && grep -q '<h2>Warnings' "$out/tall/report.html"
}
check tall_object_is_said_cut_at_its_first_view_and_at_the_end tall_test
check_summary "$out"
