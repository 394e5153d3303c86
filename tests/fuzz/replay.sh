#!/bin/sh
# make test: every fuzz target's corpus and the crashes kept, replayed (tests/fuzz/replay.c);
# a cmocka-style summary for tests/run.sh.
set -u
cd "$(dirname "$0")/../.."
pass=0
fail=0
for t in config calib view_ini scan_dir ply modbus; do
    if "${BUILD:-build}/tests/fuzz-replay-$t" "tests/fuzz/corpus/$t" "tests/fuzz/crashes/$t"; then
        pass=$((pass + 1))
    else
        echo "[  FAILED  ] fuzz replay $t"
        fail=$((fail + 1))
    fi
done
[ "$pass" -gt 0 ] && echo "[  PASSED  ] $pass test(s)."
[ "$fail" -gt 0 ] && echo "[  FAILED  ] $fail test(s)."
[ "$fail" -eq 0 ]
