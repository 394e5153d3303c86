#!/bin/sh
# make measure-calib-advice (issue 31): does a weak calibration's advice work? The demo rig
# (config/calib-demo.ini) calibrated from one placement turned to five angles (5 boards): the
# file is flagged weak and says which placements to add (--json's add_placements); those are
# captured on their own (no ball) and added with --add; then the bunny's captures, taken with
# the true rig's file, are processed with each file. Prints the sigmas, the flag, the predicted
# depth error and the model's distance to the truth and to the true file's model, before and
# after. Usage: scripts/measure-calib-advice.sh BUILD
set -eu
build=$1
out=$build/measure-calib-advice
top=$(pwd)
rm -rf "$out"
mkdir -p "$out"
# config/calib-demo.ini with absolute paths and [calibrate] placements = $1 (and more lines $2)
config() {
    sed -e "s|^calibration = \.\./|calibration = $top/|" -e "s|^calibration = \([^/]\)|calibration = $top/config/\1|" \
        -e "s|^rig = \([^/]\)|rig = $top/config/\1|" -e "s|^mesh_file = ../|mesh_file = $top/|" \
        -e "s|^placements = .*|placements = $1${2:-}|" config/calib-demo.ini
}
config "0" >"$out/five.ini"
echo "== 5 boards: one placement at five table angles"
"$build/scanner" calibrate --config "$out/five.ini" --out "$out/five.cal.ini" >"$out/five.log" 2>&1
"$build/scanner" calibrate --config "$out/five.ini" --from "$out/five.cal-captures" --out "$out/five.cal.ini" \
    --json >"$out/five.json" 2>/dev/null
add=$(/usr/bin/python3 -c 'import json, sys; r = json.load(open(sys.argv[1])); print(r.get("add_placements", ""))' "$out/five.json")
if [ -z "$add" ]; then
    echo "not weak: nothing to add"
    exit 1
fi
echo "weak: $(sed -n 's/^; weak: //p' "$out/five.cal.ini"); advice: placements = $add"
config "$add" "\nsphere_turns = 0" >"$out/added.ini"
echo "== the advised placements captured on their own, and added"
"$build/scanner" calibrate --config "$out/added.ini" --out "$out/added.cal.ini" >"$out/added.log" 2>&1 || true
"$build/scanner" calibrate --config "$out/five.ini" --from "$out/five.cal-captures" \
    --add "$out/added.cal-captures" --out "$out/both.cal.ini" --json >"$out/both.json" 2>/dev/null
echo "== the bunny, captured with the true rig's file, processed with each"
sed -e "s|^calibration = .*|calibration = $top/config/demo-rig.ini|" -e "s|^rig = .*|rig = $top/config/demo-rig.ini|" \
    -e "s|^mesh_file = ../|mesh_file = $top/|" config/calib-demo.ini >"$out/bunny.ini"
"$build/scanner" scan --config "$out/bunny.ini" --out "$out/bunny-true" --replace >"$out/bunny-true.log" 2>&1
for c in five both; do
    cp -r "$out/bunny-true" "$out/bunny-$c-src"
    cp "$out/$c.cal.ini" "$out/bunny-$c-src/calibration.ini"
    "$build/scanner" process "$out/bunny-$c-src" --out "$out/bunny-$c" --replace >"$out/bunny-$c.log" 2>&1
    "$build/mesh-compare" "$out/bunny-$c/mesh.ply" "$out/bunny-true/truth_mesh.ply" >"$out/$c-truth.compare"
    "$build/mesh-compare" --align "$out/bunny-$c/mesh.ply" "$out/bunny-true/mesh.ply" >"$out/$c-true-file.compare"
    rm -rf "$out/bunny-$c-src"
done
/usr/bin/python3 - "$out" <<'PY'
import json, re, sys
out = sys.argv[1]
rows = []
for c in ("five", "both"):
    r = json.load(open(f"{out}/{c}.json"))
    def cmp(name):
        t = open(f"{out}/{c}-{name}.compare").read()
        m = re.search(r"result -> truth: mean ([0-9.]+) mm, 95% ([0-9.]+) mm", t)
        return f"{m.group(1)} / {m.group(2)}"
    cam, proj, pose = r["camera"]["sigma"], r["projector"]["sigma"], r["pose"]["sigma"]
    rows.append([f"{r['boards']}",
                 f"{cam['fx_px']:.2f}, {cam['cx_px']:.2f}, {cam['cy_px']:.2f}",
                 f"{proj['fx_px']:.2f}, {proj['cx_px']:.2f}, {proj['cy_px']:.2f}",
                 f"{max(pose['rotation_deg']):.3f} deg, {max(pose['translation_mm']):.3f} mm",
                 r.get("weak_values", "no") if r["weak"] else "no",
                 f"{r['predicted']['depth_centre_mm']:.4f} - {r['predicted']['depth_edge_mm']:.4f}",
                 cmp("truth"), cmp("true-file")])
names = ["boards", "camera fx, cx, cy (1 sigma, px)", "projector fx, cx, cy (1 sigma, px)",
         "pose camera -> projector (largest 1 sigma)", "weak", "predicted depth error, centre - edge (mm)",
         "bunny model -> truth, mean / 95% (mm)", "bunny model -> the true file's model, aligned (mm)"]
print("| | 5 boards | with the advised placements |")
print("|---|---|---|")
for k, name in enumerate(names):
    print(f"| {name} | {rows[0][k]} | {rows[1][k]} |")
PY
