#!/usr/bin/env python3
"""make measure-inverse: make measure's tables with every bit's inverse projected, and with the
inverses of the finest 4, 3 and 2 bits only ([scan] inverse_bits), side by side: each row's valid
share (decoded right, for the objects), its wrong decodes (more than one column off) and points
more than 2 mm off, and per setting the frames a view takes and the worst loss. About 6 minutes.
    python3 scripts/measure-inverse.py BUILD"""
import subprocess
import sys

BUILD = sys.argv[1] if len(sys.argv) > 1 else "build"
CONFIGS = ["config/sim.ini", "config/sim-limit.ini", "config/sim-glossy.ini",
           "config/sim-concave.ini"]
SETTINGS = [0, 4, 3, 2]


def tables(inverse_bits):
    """{table title: [row cells]} of one measure_view run."""
    args = [f"{BUILD}/measure_view"]
    if inverse_bits:
        args += ["--inverse-bits", str(inverse_bits)]
    out = subprocess.run(args + CONFIGS, capture_output=True, text=True, check=True).stdout
    found, title = {}, "config/sim.ini: objects"
    for line in out.splitlines():
        if line.startswith("config/"):
            title = line
        elif line.startswith("| ") and not line.startswith("| object"):
            found.setdefault(title, []).append([c.strip() for c in line.strip("|").split("|")])
    return found


def pct(cell):
    return float(cell.rstrip("%"))


# per table: (the valid share's column, wrong decodes' column or None, points > 2 mm or None)
COLUMNS = {"objects": (3, None, 10), "limit": (4, 5, 8), "glossy": (4, None, None),
           "interreflections": (4, 5, 8)}


def kind(title):
    for k in COLUMNS:
        if k in title or (k == "limit" and "finest stripe" in title):
            return k
    return "objects"


runs = {n: tables(n) for n in SETTINGS}
worst = {n: 0.0 for n in SETTINGS}
points = {n: 0 for n in SETTINGS}
wrong_more = {n: 0 for n in SETTINGS}
for title, base_rows in runs[0].items():
    valid_col, wrong_col, far_col = COLUMNS[kind(title)]
    print(f"\n{title}\n")
    print("| row | valid, every inverse | " + " | ".join(f"inverse_bits {n}" for n in SETTINGS[1:]) +
          " |\n|---|---|" + "---|" * (len(SETTINGS) - 1))
    for r, row in enumerate(base_rows):
        cells = []
        for n in SETTINGS[1:]:
            other = runs[n][title][r]
            loss = pct(row[valid_col]) - pct(other[valid_col])
            worst[n] = max(worst[n], loss)
            text = f"{pct(other[valid_col]):.2f}% ({-loss:+.2f})"
            if wrong_col is not None:
                more = pct(other[wrong_col]) - pct(row[wrong_col])
                wrong_more[n] += more > 0.005
                text += f", wrong {other[wrong_col]}"
            if far_col is not None:
                points[n] += int(other[far_col])
                text += f", > 2 mm {other[far_col]}"
            cells.append(text)
        base = row[valid_col] + (f", wrong {row[wrong_col]}" if wrong_col is not None else "") + \
            (f", > 2 mm {row[far_col]}" if far_col is not None else "")
        if far_col is not None:
            points[0] += int(row[far_col])
        print(f"| {' '.join(row[:3])} | {base} | " + " | ".join(cells) + " |")

frames = {n: 2 + (10 + (n or 10)) for n in SETTINGS}  # a 1024-column projector, columns only
print("\n| inverse_bits | pattern frames a view | worst loss of valid share | rows with more wrong "
      "decodes | points > 2 mm, all rows |\n|---|---|---|---|---|")
for n in SETTINGS:
    print(f"| {n or 'every bit (0)'} | {frames[n]} | {worst[n]:.2f} points | {wrong_more[n]} | "
          f"{points[n]} |")
