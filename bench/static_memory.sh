#!/bin/sh
# Static memory of the firmware's buffers (sizes are compiled in: hal/include/hal_limits.h,
# hal/include/hal_limits.h); only the part a configuration uses is ever touched (BSS is mapped lazily).
set -eu
lib=$1
echo "| buffer (firmware/) | MiB |"
echo "|---|---|"
nm -S -t d --size-sort "$lib" 2>/dev/null | awk '$3 ~ /^[bBdD]$/ && $2 + 0 >= 65536 {
    total += $2; printf "| `%s` | %.1f |\n", $4, $2 / 1048576 } END {
    printf "| **total (compiled limits)** | **%.1f** |\n", total / 1048576 }'
