#!/bin/sh
# The scans measure-objects kept (KEEP=range or KEEP=1) registered and fused again by another
# build, each against its truth: for a change to the registration or the fusion, the same scans
# before and after without scanning them again (a scan's range images do not depend on either).
# Usage: scripts/reprocess-objects.sh BUILD SCANS_DIR [NAME...]; one line a scan: name, model ->
# truth mean (mm), registration CPU (s), whether the calibrated axis was kept unpaid (1) and how
# many turns the paint gave.
set -u
build=$1
dir=$2
shift 2
out=$build/reprocess-objects
mkdir -p "$out"
names=${*:-$(cd "$dir" && for d in */view_000/range.bin; do echo "${d%%/*}"; done)}
for n in $names; do
    rm -rf "${out:?}/$n"
    "$build/scanner" process "$dir/$n" --out "$out/$n" >"$out/$n.log" 2>&1
    mean=$("$build/mesh-compare" --align "$out/$n/mesh.ply" "$dir/$n/truth_mesh.ply" 2>/dev/null |
        sed -n 's/^result -> truth: mean \([0-9.]*\) mm.*/\1/p')
    cpu=$(sed -n 's/^registration: .*; \([0-9.]*\) s CPU.*/\1/p' "$out/$n.log")
    axis=$(sed -n 's/^axis_kept_unpaid = //p' "$out/$n/view_000/registration.ini" 2>/dev/null)
    paint=$(sed -n 's/^turns_by_paint = //p' "$out/$n/view_000/registration.ini" 2>/dev/null)
    rm -rf "${out:?}/$n"
    echo "$n ${mean:-failed} ${cpu:--} ${axis:--} ${paint:--}"
done
