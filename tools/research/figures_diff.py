#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Compares two outputs of `underfoot compare --figures --markdown` (docs/explanation/realism.md,
"Per surface and seed"), before and after a preset change, per surface: how often the nested
listeners put it in its category and named its material, at how many seeds every held-out source
placed it (and where not, who heard what), at how many its flatness lay inside the recordings'
IQR and its own material's recordings were the nearest. The summary lines of both files follow,
verbatim. The per-surface counts of the decision records (e.g.
docs/decisions/beach-sand-short-shower.md) come from this tool.

    underfoot compare --figures --seeds 1,2,...,10 --markdown > before.md
    UNDERFOOT_SURFACES_DIR=VARIANT underfoot compare --figures --seeds 1,2,...,10 --markdown > after.md
    python3 tools/research/figures_diff.py before.md after.md [--all]

Only the surfaces whose counts differ are listed (--all: every surface). A flatness is outside
the IQR when `compare` marked it so (" outside": it compares the unrounded values) or when its
printed value lies outside the printed range (tables written before the marker). The distances
are read as printed (0.01): two equal distances can count otherwise than in the summary line,
which `compare` computes unrounded.
"""
import argparse
import re
import sys

FLATNESS = re.compile(r"^(-?[\d.]+) \((-?[\d.]+)\.\.(-?[\d.]+)\)( outside)?$")


class FiguresError(Exception):
    pass


def read(path):
    """Per surface: [category right, judged, material right, flatness inside, own closest,
    seeds, seeds placed by every source, misses]; and the summary lines."""
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().splitlines()
    except OSError as e:
        raise FiguresError(f"{path}: cannot read it ({e.strerror})") from None
    surfaces, summary, header = {}, [], None
    for number, line in enumerate(lines, 1):
        if line.startswith("nested, over") or line.startswith("heard in their category"):
            summary.append(line)
        if not line.startswith("| "):
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if cells[0] == "surface":
            header = cells
            continue
        if header is None or set(cells[0]) <= set(":- "):
            continue
        if len(cells) != len(header):
            raise FiguresError(f"{path}:{number}: expected {len(header)} cells, found {len(cells)}")
        row = dict(zip(header, cells))
        s = surfaces.setdefault(row["surface"], [0, 0, 0, 0, 0, 0, 0, []])
        s[5] += 1
        if row["nested category"] == "-":
            continue
        try:
            right, judged = map(int, row["nested category"].split("/"))
            s[0] += right
            s[1] += judged
            s[2] += int(row["material"].split("/")[0])
        except (ValueError, KeyError):
            raise FiguresError(f"{path}:{number}: expected the nested columns as 'R/N' "
                               f"(a table of `underfoot compare --figures --markdown`)") from None
        if right == judged:
            s[6] += 1
        else:
            s[7].append(f"{row['seed']}: {row['other category without']}")
        flat = FLATNESS.match(row["flatness dB (IQR)"])
        if flat:
            value, low, high = map(float, flat.groups()[:3])
            s[3] += low <= value <= high and not flat.group(4)
        if row["own distance"] != "-" and row["nearest other"] != "-":
            s[4] += float(row["own distance"]) < float(row["nearest other"].split()[-1])
    if header is None:
        raise FiguresError(f"{path}: no table of `underfoot compare --figures --markdown` in it")
    return surfaces, summary


def describe(s):
    return (f"category {s[0]}/{s[1]}, material {s[2]}/{s[1]}, every source at {s[6]}/{s[5]} "
            f"seeds, flatness inside {s[3]}, own closest {s[4]}")


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--all", action="store_true", help="every surface, changed or not")
    a = parser.parse_args(argv)
    try:
        before, before_summary = read(a.before)
        after, after_summary = read(a.after)
    except FiguresError as e:
        print(f"figures_diff: {e}", file=sys.stderr)
        return 2
    for name in sorted(set(before) | set(after)):
        b, f = before.get(name), after.get(name)
        if b is None or f is None:
            print(f"{name}: only in {a.before if f is None else a.after}")
            continue
        if not a.all and b[:7] == f[:7]:
            continue
        print(f"{name}:\n  before: {describe(b)}\n  after:  {describe(f)}")
        if f[7]:
            print("  after, not placed by every source: " + "; ".join(f[7]))
    for label, lines in (("before", before_summary), ("after", after_summary)):
        for line in lines:
            print(f"{label}: {line}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
