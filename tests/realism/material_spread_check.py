#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Checks tools/research/material_spread.py on a features file whose listener geometry is known:
two sources recorded gravel on opposite sides of their hard floors, so their gravel centroids
lie twice as far apart as gravel from hard; a third source recorded hard floors only. Checks the
yardstick, the per-material pairs, --without, a render row being ignored, and the refusals.

    material_spread_check.py SOURCE_DIR SCRATCH_DIR
"""
import os
import subprocess
import sys

KEYS = ["centroid", "rolloff85", "flatness", "band_20_250", "band_250_1k", "band_1k_4k",
        "band_4k_16k", "peakiness", "grain_rate", "crest", "decay20", "attack", "active",
        "temporal_centroid"]


def row(name, source, material, centroid):
    return ",".join([name, source, material, str(centroid)] + ["0"] * (len(KEYS) - 1)) + "\n"


def main():
    source, scratch = sys.argv[1:3]
    os.makedirs(scratch, exist_ok=True)
    path = os.path.join(scratch, "features.csv")
    with open(path, "w") as f:
        f.write(",".join(["name", "source", "material"] + KEYS) + "\n")
        # Each source's median is its hard floor: centred, hard sits at 0 and gravel at +-1 on
        # the centroid; every spread is below its floor (0.5), so z = centred / 0.5.
        for s, g in (("A", 1.0), ("B", -1.0)):
            f.write(row(f"{s}1", s, "hard", 0) + row(f"{s}2", s, "hard", 0) +
                    row(f"{s}3", s, "gravel", g))
        f.write(row("C1", "C", "hard", 0) + row("C2", "C", "hard", 0))
        f.write(row("gravel", "synthetic", "gravel", 9))  # a render: not a centroid
    tool = os.path.join(source, "tools", "research", "material_spread.py")

    def run(*args):
        return subprocess.run([sys.executable, tool, path, *args], capture_output=True, text=True)

    failures = []

    def expect(args, rc, out, err=""):
        r = run(*args)
        if r.returncode != rc or r.stdout != out or err not in r.stderr:
            failures.append(f"material_spread.py {' '.join(args)}: rc {r.returncode} (expected "
                            f"{rc})\n--- stdout\n{r.stdout}--- expected\n{out}--- stderr\n"
                            f"{r.stderr}--- expected to contain\n{err}\n")

    expect([], 0,
           "different materials: median centroid distance 2.00 (IQR 2.00..2.00, 6 pairs)\n"
           "gravel: 1 of 1 source pairs farther apart than the median of different materials: "
           "A-B 4.00\n"
           "hard: 0 of 3 source pairs farther apart than the median of different materials: "
           "A-B 0.00, A-C 0.00, B-C 0.00\n")
    expect(["gravel"], 0,
           "different materials: median centroid distance 2.00 (IQR 2.00..2.00, 6 pairs)\n"
           "gravel: 1 of 1 source pairs farther apart than the median of different materials: "
           "A-B 4.00\n")
    expect(["--without", "B", "gravel"], 0,
           "different materials: median centroid distance 2.00 (IQR 2.00..2.00, 2 pairs)\n"
           "gravel: one source (A)\n")
    expect(["mud"], 1, "", "no recording of material 'mud' (recorded: gravel, hard)")
    expect(["--without", "Z"], 1, "", "no recording of source 'Z'")
    expect(["--without", "synthetic"], 1, "", "no recording of source 'synthetic'")
    if failures:
        sys.stderr.write("\n".join(failures))
        return 1
    print("material_spread.py: 6 cases as expected")
    return 0


if __name__ == "__main__":
    sys.exit(main())
