#!/bin/sh
# Two scan folders made by two builds from the same settings: every file byte for byte, but the
# lines that say when and how long (view.ini's started, finished and wall_ms; summary.ini's
# times, CPU and memory) and report.html, which shows those. For refactors that must change
# nothing (issue 29): scripts/compare-scans.sh BEFORE AFTER; exit 1 and the files that differ.
set -u
a=$1
b=$2
status=0
timeless() { grep -v -E '^(started|finished|wall_ms|elapsed_s|cpu_s|peak_memory_mb|capture|decoding|registration|reflectance fit|fusion|meshing) = ' "$1"; }
for f in $(cd "$a" && find . -type f | sort); do
    case $f in
    */report.html) continue ;;
    */view.ini | */summary.ini)
        timeless "$a/$f" > "$a.tmp.$$" && timeless "$b/$f" > "$b.tmp.$$" 2>/dev/null &&
            cmp -s "$a.tmp.$$" "$b.tmp.$$" || { echo "differs: $f"; status=1; }
        rm -f "$a.tmp.$$" "$b.tmp.$$" ;;
    *) cmp -s "$a/$f" "$b/$f" || { echo "differs: $f"; status=1; } ;;
    esac
done
for f in $(cd "$b" && find . -type f | sort); do
    [ -e "$a/$f" ] || { echo "only in $b: $f"; status=1; }
done
[ $status -eq 0 ] && echo "the same: $(cd "$a" && find . -type f | wc -l) files ($a, $b)"
exit $status
