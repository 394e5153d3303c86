# Sourced by the shell tests (tests/cli.sh, tests/calibrate.sh): check NAME COMMAND... runs a
# command that must succeed and prints a cmocka-style line for tests/run.sh, with the command's
# output indented when it fails; wait_for FILE N waits for a file (a process in the background
# getting somewhere); check_summary prints the totals and is the script's status.
# Needs $out (the test's output directory).
pass=0
fail=0
check() { # name, then a command that must succeed (its seconds said: make test stays short)
    name=$1
    shift
    start=$(date +%s)
    if "$@" >"$out.log" 2>&1; then
        echo "[       OK ] $name ($(($(date +%s) - start)) s)"
        pass=$((pass + 1))
    else
        echo "[  FAILED  ] $name"
        sed 's/^/    /' "$out.log"
        fail=$((fail + 1))
    fi
}
wait_for() { # file, at most this many looks 50 ms apart
    n=0
    while [ ! -e "$1" ] && [ "$n" -lt "$2" ]; do
        sleep 0.05
        n=$((n + 1))
    done
}
# check_summary [DIR]: when every check passed, DIR goes (its scans take gigabytes: a CI disk
# filled up once); a failure keeps it to look at.
check_summary() {
    echo "[  PASSED  ] $pass test(s)."
    [ "$fail" -eq 0 ] || echo "[  FAILED  ] $fail test(s)"
    [ "$fail" -eq 0 ] && [ -n "${1:-}" ] && rm -rf "$1"
    [ "$fail" -eq 0 ]
}
