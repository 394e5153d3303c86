#!/usr/bin/env python3
"""Peak resident memory of a running scanner, split: its static buffers (the program's BSS, the
anonymous mappings that follow its own file's, mapped as they are touched) and the rest (heap and
other mappings: in a simulated scan, mostly the simulator's rendering, which a real rig has not).
Samples /proc/PID/smaps every 0.1 s until the process ends; prints one line of MB:
    static PEAK_STATIC rest PEAK_REST all PEAK_ALL
Usage: rss_split.py PID"""
import os
import sys
import time


def sample(pid, exe):
    """(kB resident in the program's static buffers, kB resident in all), or None once gone."""
    try:
        with open(f"/proc/{pid}/smaps") as f:
            lines = f.read().splitlines()
    except OSError:
        return None
    static = total = 0
    chain_end = None  # where the executable's mappings and the BSS after them end so far
    current_static = False
    for line in lines:
        head = line.split()
        if "-" in head[0] and len(head) >= 5 and not head[0].endswith(":"):
            lo, hi = (int(x, 16) for x in head[0].split("-"))
            path = head[5] if len(head) > 5 else ""
            current_static = False
            if path == exe:
                chain_end = hi
            elif path == "" and chain_end is not None and lo == chain_end:
                chain_end = hi
                current_static = True
            else:
                chain_end = None
        elif head[0] == "Rss:":
            kb = int(head[1])
            total += kb
            if current_static:
                static += kb
    return static, total


def main():
    pid = int(sys.argv[1])
    peak_static = peak_rest = peak_all = 0
    try:
        exe = os.readlink(f"/proc/{pid}/exe")
    except OSError:
        exe = None  # gone already (or never was): nothing sampled
    while exe is not None:
        got = sample(pid, exe)
        if got is None:
            break
        static, total = got
        peak_static = max(peak_static, static)
        peak_rest = max(peak_rest, total - static)
        peak_all = max(peak_all, total)
        time.sleep(0.1)
    print(f"static {peak_static / 1024:.0f} rest {peak_rest / 1024:.0f} all {peak_all / 1024:.0f}")


main()
