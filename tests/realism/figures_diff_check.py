#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Checks tools/research/figures_diff.py on two small tables shaped as `underfoot compare
--figures --markdown` prints them: the per-surface counts, that an unchanged surface is left
out, the misses of the table after, a flatness marked outside though printed at the IQR's edge,
the summary lines, and the refusal of a file without a table.

    figures_diff_check.py SOURCE_DIR SCRATCH_DIR
"""
import os
import subprocess
import sys

HEADER = ("| surface | seed | nested category | material | other category without | own distance "
          "| nearest other | flatness dB (IQR) | centroid Hz (IQR) | ns/frame |\n"
          "| :--- | ---: | ---: | ---: | :--- | :--- | :--- | :--- | :--- | :--- |\n")


def row(surface, seed, category, material, without, own, other, flatness):
    return (f"| {surface} | {seed} | {category} | {material} | {without} | {own} | {other} "
            f"| {flatness} | 300 (200..900) | 100 |\n")


def main():
    source, scratch = sys.argv[1:3]
    os.makedirs(scratch, exist_ok=True)
    unchanged = [("carpet", 1, "1/1", "0/1", "-", "1.22", "wood 1.51", "-30.6 (-37.0..-15.5)"),
                 ("dry_leaves", 1, "-", "-", "-", "-", "-", "-")]
    tables = {
        "before": [("beach_sand", 1, "1/2", "0/2", "minetest:hard (0/3)", "0.30", "dirt 0.60",
                    "-14.0 (-14.6..-10.0)"),
                   ("beach_sand", 2, "1/2", "0/2", "minetest:hard (0/3)", "0.70", "dirt 0.60",
                    "-14.0 (-14.6..-10.0)")],
        "after": [("beach_sand", 1, "2/2", "1/2", "-", "0.40", "dirt 0.70", "-15.1 (-14.6..-10.0)"),
                  # printed at the IQR's edge, marked outside by `compare` (unrounded)
                  ("beach_sand", 2, "1/2", "1/2", "minetest:hard (0/3)", "0.40", "dirt 0.70",
                   "-14.6 (-14.6..-10.0) outside")],
    }
    summaries = {"before": "3/5", "after": "4/5"}
    for name, rows in tables.items():
        with open(os.path.join(scratch, f"{name}.md"), "w") as f:
            f.write("Per surface and render seed ...\n\n" + HEADER)
            f.write("".join(row(*r) for r in rows + unchanged))
            f.write(f"\nnested, over 2 seeds: category right {summaries[name]}\n")
    before = os.path.join(scratch, "before.md")
    after = os.path.join(scratch, "after.md")
    empty = os.path.join(scratch, "empty.md")
    with open(empty, "w") as f:
        f.write("no table here\n")
    tool = os.path.join(source, "tools", "research", "figures_diff.py")

    def run(*args):
        return subprocess.run([sys.executable, tool, *args], capture_output=True, text=True)

    r = run(before, after)
    expected = (
        "beach_sand:\n"
        "  before: category 2/4, material 0/4, every source at 0/2 seeds, flatness inside 2, "
        "own closest 1\n"
        "  after:  category 3/4, material 2/4, every source at 1/2 seeds, flatness inside 0, "
        "own closest 2\n"
        "  after, not placed by every source: 2: minetest:hard (0/3)\n"
        "before: nested, over 2 seeds: category right 3/5\n"
        "after: nested, over 2 seeds: category right 4/5\n")
    if r.returncode != 0 or r.stdout != expected:
        print(f"FAIL: exit {r.returncode}\n--- got\n{r.stdout}{r.stderr}--- expected\n{expected}")
        return 1
    r = run(before, after, "--all")
    if "carpet:" not in r.stdout or "dry_leaves:" not in r.stdout:
        print(f"FAIL: --all leaves out an unchanged surface:\n{r.stdout}")
        return 1
    r = run(empty, after)
    if r.returncode != 2 or f"{empty}: no table" not in r.stderr:
        print(f"FAIL: a file without a table: exit {r.returncode}, {r.stderr!r}")
        return 1
    print("ok: figures_diff counts per surface, lists the misses, refuses a file without a table")
    return 0


if __name__ == "__main__":
    sys.exit(main())
