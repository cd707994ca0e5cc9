#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Is a material one material for the listener? Distances between the sources' centroids of it
(docs/decisions/frozen-snow-and-gravel-trade-off.md, "What a third recordist does").

    underfoot compare --listener --features features.csv
    python3 tools/research/material_spread.py features.csv [--without SOURCE] [MATERIAL ...]

Rebuilds the listener of `underfoot compare --listener` (realism/Listener.cpp, as
category_why.py does: every source centred on its own median, standardised by the recordings'
pooled median and IQR / 1.349, one centroid per (source, material)) and prints:

  - the yardstick: the median Euclidean distance between two centroids of different materials
    (any sources), and its interquartile range;
  - per material recorded by two sources or more: the distance between every two sources'
    centroids of it, and how many of those pairs lie farther apart than the yardstick.

A material whose sources' centroids lie farther apart than two different materials usually do
cannot be learnt from one source and recognised in another: a render faithful to one recordist
is then heard as another material by the listener trained without that recordist. Pure Python.
"""
import itertools
import math
import sys

from category_why import parse_args, read, train
from listener_common import quantile


def main(argv):
    without, args, _ = parse_args(argv, __doc__)
    path, only = args[0], set(args[1:])
    ex = read(path)
    rec, cents = train(ex, without, path)
    if not rec:
        sys.exit(f"{path}: no recordings (every row is a render, source 'synthetic')")
    materials = sorted({m for m, _, _ in cents})
    unknown = only - set(materials)
    if unknown:
        sys.exit(f"{path}: no recording of material '{sorted(unknown)[0]}' "
                 f"(recorded: {', '.join(materials)})")
    apart = [math.dist(a[2], b[2]) for a, b in itertools.combinations(cents, 2) if a[0] != b[0]]
    if not apart:
        sys.exit(f"{path}: one material only: nothing to compare a spread with")
    yard = quantile(apart, .5)
    print(f"different materials: median centroid distance {yard:.2f} "
          f"(IQR {quantile(apart, .25):.2f}..{quantile(apart, .75):.2f}, {len(apart)} pairs)")
    for m in materials:
        if only and m not in only:
            continue
        own = [c for c in cents if c[0] == m]
        if len(own) < 2:
            print(f"{m}: one source ({own[0][1]})")
            continue
        pairs = [(math.dist(a[2], b[2]), a[1], b[1]) for a, b in itertools.combinations(own, 2)]
        far = sum(1 for d, _, _ in pairs if d > yard)
        print(f"{m}: {far} of {len(pairs)} source pairs farther apart than the median of "
              f"different materials: " + ", ".join(f"{a}-{b} {d:.2f}" for d, a, b in pairs))


if __name__ == "__main__":
    main(sys.argv)
