#!/bin/sh
# Static memory of the scanner's buffers of 64 KiB and more (sizes are compiled in:
# hal/include/hal_limits.h): the firmware's own and the contexts its owners keep static for it
# (app/job.c's view context and fusion volume, the frame writer's copies); only the part a
# configuration uses is ever touched (BSS is mapped lazily). Usage: static_memory.sh BUILD/scanner
set -eu
bin=$1
echo "| buffer | MiB |"
echo "|---|---|"
nm -S -t d --size-sort "$bin" | awk '$3 ~ /^[bBdD]$/ && $2 + 0 >= 65536 {
    total += $2; printf "| `%s` | %.1f |\n", $4, $2 / 1048576 } END {
    printf "| **total (compiled limits)** | **%.1f** |\n", total / 1048576 }'
