#!/bin/sh
# Stack frames of the firmware (gcc -fstack-usage .su files): every function's frame at most
# LIMIT bytes, and none unbounded (a VLA or alloca). Prints the largest frames.
# Usage: scripts/check-stack.sh LIMIT FILE.su...
set -eu
limit=$1
shift
for f in "$@"; do
    [ -f "$f" ] || { echo "check-stack: $f missing (built without -fstack-usage?)"; exit 1; }
done
cat "$@" | awk -F'\t' -v limit="$limit" '
    { split($1, where, ":"); fn = where[4]; size = $2 + 0
      line[NR] = sprintf("%6d  %s  %s", size, $1, $3)
      if (size > limit) { print "check-stack: " $1 ": frame of " size " bytes > " limit; bad = 1 }
      if ($3 == "dynamic") { print "check-stack: " $1 ": unbounded stack (VLA or alloca)"; bad = 1 }
      if (size > max) max = size
      n++ }
    END { printf "check-stack: %d firmware functions, largest frame %d bytes (limit %d)\n", n, max, limit
          exit bad }'
