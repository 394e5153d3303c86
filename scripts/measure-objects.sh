#!/bin/sh
# make measure-objects: the object corpus scanned as a new user would (tests/objects.ini: every
# default, no [colour] section), one table (issue 30). Mechanical parts from OpenSCAD
# (data/objects/*.scad, made into PLY at run time: openscad, then tools/off2ply.awk), the
# simulator's sphere, cylinder and torus, and two scanned meshes, the Stanford bunny and
# armadillo. For each object: every view count with [colour] method none and multi and the table
# exact; at 8 views the table 1 and 2 degrees off; at 8 views a 6 mm and a 30 mm slip after 170
# degrees, and at 6 views the 30 mm one (push6: the pairs across it see the faces it slid along);
# in 4, 6 and 8 views stood off the table's axis (offaxis: at 20, 0; 0, 30 and 30, 20 mm), as a
# person puts it down. Columns: finished (and how the views after a slip were placed) or the error, the
# model against the truth once aligned (mean, mm), the truth within 1 mm of the model (above the
# table), holes and pieces of the model, and the registration's CPU.
# Usage: scripts/measure-objects.sh BUILD; OBJECTS="box gear", VIEWS="4 8", METHODS="none" and
# CONDITIONS="exact" (exact table1 table2 slip slip30 push6; slip6v and slip12v: the 6 mm slip in 6 and 12 views;
# offaxis: the object stood off the table's axis, three places, in 4, 6 and 8 views) choose a subset; KEEP=1 keeps each
# scan and its frames (scanner process DIR computes a scan again from them); KEEP=range keeps
# each scan without its frames (its range images: enough to register and fuse it again, about
# 8 MB a view, scripts/reprocess-objects.sh); else only its log and its comparison with the
# truth are kept.
set -eu
build=$1
out=$build/measure-objects
top=$(pwd)
objects=${OBJECTS:-"box thin_box l_bracket plate_holes hex_nut gear stepped_block cup cone sphere cylinder torus bunny armadillo"}
views_list=${VIEWS:-"3 4 6 8 12 24"}
methods=${METHODS:-"none multi"}
conditions=${CONDITIONS:-"exact table1 table2 slip slip30 push6 offaxis"}
command -v openscad >/dev/null 2>&1 || {
    echo "measure-objects: openscad is missing (make measure-objects installs it)" >&2
    exit 1
} # without it every part would silently be the simulator's default object
mkdir -p "$out/parts"
parts=$(cd "$out/parts" && pwd) # configs name files relative to themselves: absolute paths

# [sim] lines of object $1: a part of data/objects at its own height, or the simulator's own
sim_lines() {
    case $1 in
    sphere | cylinder | torus) printf 'object = %s\nobject_height_mm = 100\n' "$1" ;;
    bunny) printf 'object = mesh\nmesh_file = %s/data/bunny/bun_zipper.ply\nobject_height_mm = 150\n' "$top" ;;
    armadillo) printf 'object = mesh\nmesh_file = %s/data/armadillo/armadillo.ply\nobject_height_mm = 150\n' "$top" ;;
    *)
        if [ ! -f "$parts/$1.ply" ]; then
            openscad -o "$parts/$1.off" "data/objects/$1.scad" >"$parts/$1.log" 2>&1
            awk -f tools/off2ply.awk "$parts/$1.off" >"$parts/$1.ply"
        fi
        h=$(awk 'NR > 1 && NF == 3 && $3 + 0 == $3 { if (!n++ || $3 > hi) hi = $3; if (n == 1 || $3 < lo) lo = $3 }
            END { print hi - lo }' "$parts/$1.off")
        printf 'object = mesh\nmesh_file = %s\nobject_height_mm = %s\n' "$parts/$1.ply" "$h" ;;
    esac
}
# the config of object $1, $2 views, method $3, extra [sim] lines $4, into $out/$5.ini
config() {
    sed -e "/^object = /d" -e "/^object_height_mm = /d" -e "s/^views = .*/views = $2/" \
        -e "s|^calibration = ../|calibration = $top/|" tests/objects.ini >"$out/$5.ini"
    sim_lines "$1" | sed -i "/^\[sim\]/r /dev/stdin" "$out/$5.ini"
    printf "$4" | sed -i "/^\[sim\]/r /dev/stdin" "$out/$5.ini"
    [ "$3" = none ] || printf '\n[colour]\nmethod = %s\nwhite_scale = 0.008333, 0.008333, 0.008333\n' "$3" >>"$out/$5.ini"
    # 250 scans' frames would be 60 GB; KEEP=1 keeps them, to compute scans again
    [ "${KEEP:-0}" = 1 ] || printf '\n[output]\nkeep_frames = none\n' >>"$out/$5.ini"
}
row() { # object, views, method, table, name: scan it and print its row
    rm -rf "${out:?}/$5"
    if "$build/scanner" scan --config "$out/$5.ini" --out "$out/$5" >"$out/$5.log" 2>&1; then
        result=finished
        placed=$(grep -o "moved on the table at view [0-9]*: [0-9]* views* placed by the object's [a-z ]*" "$out/$5.log" | head -n 1 || true)
        [ -z "$placed" ] || result="finished; $(echo "$placed" | sed "s/ the object's / /")"
        "$build/mesh-compare" --align "$out/$5/mesh.ply" "$out/$5/truth_mesh.ply" >"$out/$5.compare" 2>&1 || true
        mean=$(sed -n 's/^result -> truth: mean \([0-9.]*\) mm.*/\1/p' "$out/$5.compare")
        within=$(sed -n 's/^truth above the table (z >= 1 mm) -> result: mean [0-9.]* mm, within 1 mm \([0-9.]*\)%.*/\1/p' "$out/$5.compare")
        holes=$(sed -n 's/^result holes: \([0-9]*\) .*/\1/p' "$out/$5.compare")
        pieces=$(sed -n 's/^result triangles: [0-9]* in \([0-9]*\) connected.*/\1/p' "$out/$5.compare")
    else
        result=$(grep -o 'error: .*' "$out/$5.log" | head -n 1 | cut -c8-90)
        mean=- within=- holes=- pieces=-
    fi
    # a scan's views are 20 to 30 MB each without frames (range images, the simulator's truth):
    # four runs' scans kept filled this machine's 80 GB free; KEEP=1 keeps them
    case ${KEEP:-0} in
    1) ;;
    range) rm -f "$out/$5"/view_*/truth_*.pfm "$out/$5"/view_*/truth_*.png ;;
    *) rm -rf "${out:?}/$5" ;;
    esac
    cpu=$(sed -n 's/^registration: .*; \([0-9.]*\) s CPU.*/\1/p' "$out/$5.log")
    note=$(grep -o "does not fix the [a-z' ]*turn" "$out/$5.log" | head -n 1 || true)
    printf '| %s | %s | %s | %s | %s | %s | %s%% | %s | %s | %s | %s |\n' "$1" "$2" "$3" "$4" "$result" \
        "${mean:--}" "${within:--}" "${holes:--}" "${pieces:--}" "${cpu:--}" "${note:+table's turn kept}"
}

echo "| object | views | colour | table | result | model -> truth mean mm | truth within 1 mm | holes | pieces | registration CPU s | note |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for obj in $objects; do
    for views in $views_list; do
        for method in $methods; do
            case " $conditions " in *" exact "*)
                config "$obj" "$views" "$method" "" "$obj-$views-$method"
                row "$obj" "$views" "$method" exact "$obj-$views-$method" ;;
            esac
        done
    done
    for c in $conditions; do
        case $c in
        table1) config "$obj" 8 none "table_angle_error_mdeg = 1000\n" "$obj-table1"
            row "$obj" 8 none "1 deg off" "$obj-table1" ;;
        table2) config "$obj" 8 none "table_angle_error_mdeg = 2000\n" "$obj-table2"
            row "$obj" 8 none "2 deg off" "$obj-table2" ;;
        slip) config "$obj" 8 none "slip_mm = 6, 0, 0\nslip_at_deg = 170\n" "$obj-slip"
            row "$obj" 8 none "6 mm slip" "$obj-slip" ;;
        slip30) config "$obj" 8 none "slip_mm = 30, 0, 0\nslip_at_deg = 170\n" "$obj-slip30"
            row "$obj" 8 none "30 mm slip" "$obj-slip30" ;;
        push6) config "$obj" 6 none "slip_mm = 30, 0, 0\nslip_at_deg = 170\n" "$obj-push6"
            row "$obj" 6 none "30 mm slip" "$obj-push6" ;;
        slip6v) config "$obj" 6 none "slip_mm = 6, 0, 0\nslip_at_deg = 170\n" "$obj-slip6v"
            row "$obj" 6 none "6 mm slip" "$obj-slip6v" ;;
        slip12v) config "$obj" 12 none "slip_mm = 6, 0, 0\nslip_at_deg = 170\n" "$obj-slip12v"
            row "$obj" 12 none "6 mm slip" "$obj-slip12v" ;;
        offaxis) for v in 4 6 8; do
                for at in "20, 0" "0, 30" "30, 20"; do
                    name="$obj-$v-off$(echo "$at" | tr -d ' ,')"
                    config "$obj" $v none "object_offset_mm = $at\n" "$name"
                    row "$obj" $v none "$at mm off the axis" "$name"
                done
            done ;;
        esac
    done
done
