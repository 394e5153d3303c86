#!/bin/sh
# The scanner program as a user meets it: version, config errors, a scan, and its PLY in Open3D.
# Prints cmocka-style PASSED/FAILED lines for tests/run.sh.
set -u
cd "$(dirname "$0")/.."
bin=${BUILD:-build}/scanner
out=${BUILD:-build}/cli
pass=0
fail=0
check() { # name, then a command that must succeed
    name=$1
    shift
    if "$@" >"$out.log" 2>&1; then
        echo "[       OK ] $name"
        pass=$((pass + 1))
    else
        echo "[  FAILED  ] $name"
        sed 's/^/    /' "$out.log"
        fail=$((fail + 1))
    fi
}
mkdir -p "$out"
check version sh -c "$bin --version | grep -q 'HAL=sim'"
check check_config sh -c "$bin check-config --config config/sim.ini | grep -q ': ok'"
printf '[camera]\nbackend = sim\nwidth = 1280\nheight = 960\nexposure_us = 10000\nexposur = 1\n' >"$out/bad.ini"
check bad_config_names_file_line_key sh -c \
    "$bin scan --config $out/bad.ini 2>&1 | grep -q '$out/bad.ini:6: \[camera\] exposur: unknown key'"
check bad_config_exit_code sh -c "$bin scan --config $out/bad.ini; test \$? -eq 2"
rm -rf "$out/scan" "$out/broken" "$out/broken_out"
check scan sh -c "$bin scan --config config/sim.ini --out $out/scan | grep -q 'scan finished'"
check scan_dir_complete sh -c "for f in config.ini calibration.ini view_000/cloud.ply view_000/frame_00.png \
    view_000/frame_21.png view_000/view.ini view_000/truth_depth_mm.pfm view_000/truth_albedo.png; do \
    test -s $out/scan/\$f || exit 1; done"
rm -rf "$out/processed"
check process_reproduces_scan sh -c "$bin process $out/scan --out $out/processed >/dev/null && \
    cmp $out/scan/view_000/cloud.ply $out/processed/view_000/cloud.ply"
check json_events sh -c "$bin process $out/scan --out $out/processed --json | /usr/bin/python3 -c '
import json, sys
events = [json.loads(line)[\"event\"] for line in sys.stdin]
assert events[0] == \"process_start\" and events[-1] == \"process_done\" and \"saved\" in events, events'"
cp -r "$out/scan" "$out/broken" 2>/dev/null; rm -f "$out/broken/view_000/frame_07.png"
check process_names_missing_frame sh -c "$bin process $out/broken --out $out/broken_out 2>&1 | \
    grep -q 'view_000/frame_07.png: No such file'; test \$? -eq 0"
# SIGINT mid-scan: the scan stops between frames, says so, and the rig ends in its safe state.
sigint_test() {
    "$bin" scan --config config/sim.ini --out "$out/interrupted" >"$out/int.log" 2>&1 &
    pid=$!
    sleep 0.4
    kill -INT "$pid"
    wait "$pid"
    rc=$?
    cat "$out/int.log"
    [ "$rc" -eq 1 ] && grep -q 'stopped by request' "$out/int.log" &&
        grep -q 'safe state: lights and projector off' "$out/int.log"
}
check sigint_stops_safely sigint_test
points=$(sed -n 's/^valid_points = //p' "$out/scan/view_000/view.ini")
if /usr/bin/python3 -c 'import open3d' 2>/dev/null; then
    check open3d_reads_ply /usr/bin/python3 tests/interop_open3d.py "$out/scan/view_000/cloud.ply" "$points"
    check open3d_reads_mesh_ply_and_obj /usr/bin/python3 tests/interop_open3d.py --mesh "$out/scan"
else
    echo "[  FAILED  ] open3d_reads_ply: python3-open3d missing (scripts/install-deps.sh test)"
    fail=$((fail + 1))
fi
echo "[  PASSED  ] $pass test(s)."
[ "$fail" -eq 0 ] || echo "[  FAILED  ] $fail test(s)"
[ "$fail" -eq 0 ]
