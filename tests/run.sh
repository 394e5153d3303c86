#!/bin/sh
# Runs every test binary given, and ends with one line: "N passed, N failed".
# A binary that crashes or exits non-zero without cmocka's summary counts as one failure.
# RUN_WITH runs each test binary through an emulator or checker (make test-arm64: qemu-aarch64;
# make test VALGRIND=1: valgrind memcheck).
set -u
cd "$(dirname "$0")/.."
passed=0
failed=0
for t in "$@"; do
    case $t in
    *.sh) out=$("$t" 2>&1) ;;                  # scripts run the scanner themselves
    *) out=$(${RUN_WITH:-} "$t" 2>&1) ;;
    esac
    rc=$?
    printf '%s\n' "$out"
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
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
