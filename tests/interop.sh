#!/bin/sh
# Modbus interoperability with python3-pymodbus (a stack nobody on the team wrote), over TCP
# and over RTU on socat pseudo-terminal pairs, both directions. Prints cmocka-style lines.
set -u
cd "$(dirname "$0")/.."
B=${BUILD:-build}
dir=$(mktemp -d)
pass=0
fail=0
pids=""
cleanup() { for p in $pids; do kill "$p" 2>/dev/null; done; rm -rf "$dir"; }
trap cleanup EXIT
result() { # name rc log
    if [ "$2" -eq 0 ]; then echo "[       OK ] $1"; pass=$((pass + 1));
    else echo "[  FAILED  ] $1"; sed 's/^/    /' "$3"; fail=$((fail + 1)); fi
}
free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
wait_for() { i=0; while ! eval "$1" && [ $i -lt 100 ]; do sleep 0.05; i=$((i + 1)); done; }
pty_pair() { # $1: name; makes $dir/$1A and $dir/$1B
    socat pty,raw,echo=0,link="$dir/${1}A" pty,raw,echo=0,link="$dir/${1}B" 2>/dev/null &
    pids="$pids $!"
    wait_for "[ -e $dir/${1}A ] && [ -e $dir/${1}B ]"
}

# 1. the scanner's client against a pymodbus controller, TCP
port=$(free_port)
/usr/bin/python3 tests/interop_pymodbus.py server-tcp "$port" >"$dir/s1.log" 2>&1 &
pids="$pids $!"
wait_for "$B/tt-client tcp 127.0.0.1 $port status >/dev/null 2>&1"
$B/tt-client tcp 127.0.0.1 "$port" status home move 123456 status move -90000 status >"$dir/c1.log" 2>&1 &&
    grep -q 'position_mdeg=-90000 busy=0 homed=1 alarm=0' "$dir/c1.log"
result pymodbus_server_tcp $? "$dir/c1.log"

# 2. the same over RTU on a socat pty pair
pty_pair rtu1
/usr/bin/python3 tests/interop_pymodbus.py server-rtu "$dir/rtu1B" >"$dir/s2.log" 2>&1 &
pids="$pids $!"
sleep 1
$B/tt-client rtu "$dir/rtu1A" 19200 none 1 status home move 45000 status >"$dir/c2.log" 2>&1 &&
    grep -q 'position_mdeg=45000 busy=0 homed=1 alarm=0' "$dir/c2.log"
result pymodbus_server_rtu $? "$dir/c2.log"

# 3. build/turntable-sim answering a pymodbus client, TCP
$B/turntable-sim --tcp 127.0.0.1:0 >"$dir/t3.log" 2>&1 &
pids="$pids $!"
wait_for "grep -q listening $dir/t3.log"
port=$(sed -n 's/.*listening on .*:\([0-9]*\)$/\1/p' "$dir/t3.log")
/usr/bin/python3 tests/interop_pymodbus.py client-tcp "$port" >"$dir/c3.log" 2>&1
result turntable_sim_pymodbus_client_tcp $? "$dir/c3.log"

# 4. the same over RTU
pty_pair rtu2
$B/turntable-sim --rtu "$dir/rtu2B" --baud 19200 --parity none --unit 1 >"$dir/t4.log" 2>&1 &
pids="$pids $!"
wait_for "grep -q serving $dir/t4.log"
/usr/bin/python3 tests/interop_pymodbus.py client-rtu "$dir/rtu2A" >"$dir/c4.log" 2>&1
result turntable_sim_pymodbus_client_rtu $? "$dir/c4.log"

echo "[  PASSED  ] $pass test(s)."
[ "$fail" -eq 0 ] || echo "[  FAILED  ] $fail test(s)"
[ "$fail" -eq 0 ]
