#!/bin/sh
# The layer rule of docs/architecture.md, shown on the real build: a file placed in a layer that
# includes a header of a layer above it (or beside it) does not compile, with the Makefile's own
# flags for that directory; the same file including what the layer may see does.
# Prints cmocka-style PASSED/FAILED lines for tests/run.sh.
set -u
cd "$(dirname "$0")/.."
pass=0
fail=0
probe=layer_probe_
trap 'rm -f firmware/$probe.c hal/posix/$probe.c hal/modbus/$probe.c hal/linux/$probe.c host_sim/$probe.c board/$probe.c app/$probe.c calib/$probe.c web/$probe.c' EXIT
# dir, header, expect (fail | ok)
try() {
    dir=$1 header=$2 expect=$3
    printf '/* layer probe */\n#include "%s"\nint layer_probe_(void);\nint layer_probe_(void) { return 0; }\n' \
        "$header" > "$dir/$probe.c"
    rm -f "build/layer-probe/$dir/$probe.o" # an object of the try before would be taken as this one
    log=$(make -s "build/layer-probe/$dir/$probe.o" BUILD=build/layer-probe 2>&1)
    rc=$?
    rm -f "$dir/$probe.c"
    case $expect in
    fail) [ $rc -ne 0 ] && printf '%s' "$log" | grep -q "$header: No such file" ;;
    ok) [ $rc -eq 0 ] ;;
    esac
    if [ $? -eq 0 ]; then
        echo "[       OK ] $dir includes $header: $expect"
        pass=$((pass + 1))
    else
        echo "[  FAILED  ] $dir includes $header: expected $expect"
        printf '%s\n' "$log" | sed 's/^/    /'
        fail=$((fail + 1))
    fi
}
try firmware config.h fail      # app/
try firmware board.h fail       # board/
try firmware sim_rig.h fail     # host_sim/
try firmware storage_posix.h fail
try firmware hal.h ok
try hal/posix config.h fail
try hal/modbus board.h fail
try hal/linux scan.h fail       # firmware/: a backend knows only the interface it fills
try hal/linux hal.h ok
try host_sim config.h fail
try host_sim scan_job.h fail
try host_sim board.h fail
try host_sim storage_posix.h fail
try host_sim frames.h ok        # agrees with the firmware on frames
try board config.h fail         # the board does not reach up into the program that drives it
try board scan_job.h fail
try board sim_rig.h ok
try app web.h fail              # the scanner program knows nothing of the web server
try firmware api.h fail
try web gpio_gpiod.h fail       # the web server never drives a device: scanner does
try web camera_v4l2.h fail
try web report.h ok             # it shows the report's pictures
try app calibrate.h fail        # the calibration is its own layer on app/, and its own program
try web calibrate.h fail        # (config.h holds only its [calibrate] settings)
try app calib_cv.h fail
try calib web.h fail
try calib config.h ok           # it loads configs and scans with app/'s code
try calib scan_job.h ok
echo "[==========] $((pass + fail)) test(s) run."
echo "[  PASSED  ] $pass test(s)."
[ $fail -eq 0 ] || echo "[  FAILED  ] $fail test(s)."
[ $fail -eq 0 ]
