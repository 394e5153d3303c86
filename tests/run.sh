#!/bin/sh
# Runs every test binary given, and ends with one line: "N passed, N failed".
# A binary that crashes or exits non-zero without cmocka's summary counts as one failure.
# RUN_WITH runs each test binary through an emulator or checker (make test-arm64: qemu-aarch64;
# make test VALGRIND=1: valgrind memcheck).
# "A... -- B...": the tests B run beside A, in a second process (the machine has two cores and
# most tests use one); B's output follows A's, and the last line counts both.
set -u
cd "$(dirname "$0")/.."
first=""
second=""
split=0
for t in "$@"; do
    if [ "$t" = "--" ]; then
        split=1
    elif [ $split -eq 1 ]; then
        second="$second $t"
    else
        first="$first $t"
    fi
done
side_log=""
if [ -n "$second" ]; then
    side_log=$(mktemp)
    # shellcheck disable=SC2086 # the list is word-split on purpose
    "$0" $second >"$side_log" 2>&1 &
    side=$!
fi
passed=0
failed=0
for t in $first; do
    start=$(date +%s)
    case $t in
    # Scripts run the scanner themselves, hundreds of times: under ASan (make test SAN=1) the
    # leak check at each exit scans the gigabyte of static buffers, 2 to 5 s a process (cli.sh
    # took 21 minutes, its error table alone 8), so they leave it off unless ASAN_OPTIONS says
    # otherwise; the unit tests keep it, and the scripts turn it on for the main commands (a
    # scan, process, calibrate: detect_leaks=1 there).
    *.sh) out=$(ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0}" "$t" 2>&1) ;;
    *) out=$(${RUN_WITH:-} "$t" 2>&1) ;;
    esac
    rc=$?
    printf '%s\n' "$out"
    echo "[   TIME   ] $t: $(($(date +%s) - start)) s" # make test stays under 10 minutes
    p=$(printf '%s\n' "$out" | sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' | tail -n 1)
    f=$(printf '%s\n' "$out" | sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' | tail -n 1)
    p=${p:-0}
    f=${f:-0}
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
        echo "$t: exited with $rc"
        f=1
    fi
    passed=$((passed + p))
    failed=$((failed + f))
done
if [ -n "$side_log" ]; then
    wait "$side" || true
    cat "$side_log"
    counts=$(tail -n 1 "$side_log")
    p=$(printf '%s\n' "$counts" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\1/p')
    f=$(printf '%s\n' "$counts" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\2/p')
    if [ -z "$p" ]; then
        echo "tests run beside:$second: no summary (killed?)"
        p=0
        f=1
    fi
    passed=$((passed + p))
    failed=$((failed + f))
    rm -f "$side_log"
fi
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
