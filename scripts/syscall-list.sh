#!/bin/sh
# The system calls a unit's SystemCallFilter= lines allow, one a line, as systemd computes them:
# the first list allows (groups expanded with systemd-analyze syscall-filter), each later list
# starting with ~ takes its calls away. Usage: scripts/syscall-list.sh UNIT_FILE
set -eu
expand() { # names and @groups -> names
    for item in "$@"; do
        case $item in
        @*) expand $(systemd-analyze syscall-filter "$item" | sed -n 's/^    \([@a-z0-9_-]*\)$/\1/p') ;;
        *) echo "$item" ;;
        esac
    done
}
allow=$(mktemp)
deny=$(mktemp)
trap 'rm -f "$allow" "$deny"' EXIT
sed -n 's/^SystemCallFilter=//p' "$1" | while read -r line; do
    case $line in
    "~"*) expand ${line#\~} >>"$deny" ;;
    *) expand $line >>"$allow" ;;
    esac
done
sort -u "$allow" | grep -vxF -f "$deny" || true
