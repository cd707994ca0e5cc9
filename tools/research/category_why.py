#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Why the listener hears a render in another category (docs/decisions/realism-revoicing.md, "Heard in their
category: liquids, snows, leaves and underbrush").

    underfoot compare --listener --features features.csv
    python3 tools/research/category_why.py features.csv [--all] [--without SOURCE] [ID ...]

Reads the per-file listener features written by `compare --features` and rebuilds the default
listener of realism/Listener.cpp exactly (every source, the renders as source "synthetic"
included, centred on its own per-feature median; the 14 scalar descriptors standardised by the
recordings' pooled median and IQR / 1.349 with the descriptors' floors; one centroid per
(source, material); nearest centroid in Euclidean distance). For every render it prints:

  - the material heard (nearest centroid) and the nearest centroid of the render's own
    category, with both distances;
  - per descriptor, how much it pulls the render towards the heard centroid rather than the
    own-category one: z_own^2 - z_heard^2 (the squared distances are sums of these, so the
    terms add up to d_own^2 - d_heard^2 and a positive term is a reason for the wrong verdict);
  - per descriptor, the render's centred, standardised value beside the recorded files of its
    own category (centred the same way): median and interquartile range, and "<" or ">" when
    the render lies below or above that range; then the heard and the own-category centroid.

Without --all only the renders heard in another category are shown. --without SOURCE is the
nested listener of `compare --listener`: trained (standardised, centroids) without that source's
recordings, every source still centred on its own median. Pure Python, no numpy.
"""
import csv
import math
import sys

from listener_common import CATEGORY, FLOORS, KEYS, NS, quantile

# Bundled surfaces without a recorded material (engine/data/surfaces/*.toml `category`).
SURFACE_CATEGORY = {"dry_leaves": "aggregate", "forest_underbrush": "aggregate"}


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    head = rows[0]
    if head[:3] != ["name", "source", "material"] or head[3:3 + NS] != KEYS:
        sys.exit(f"{path}: line 1: expected the header of `underfoot compare --features`")
    out = []
    for i, r in enumerate(rows[1:], start=2):
        if len(r) != len(head):
            sys.exit(f"{path}: line {i}: {len(r)} columns, expected {len(head)}")
        try:
            feats = [float(x) for x in r[3:3 + NS]]
        except ValueError:
            sys.exit(f"{path}: line {i}: a feature is not a number")
        out.append({"name": r[0], "source": r[1], "material": r[2], "f": feats})
    return out


def centre_by_source(ex):
    for s in {e["source"] for e in ex}:
        es = [e for e in ex if e["source"] == s]
        med = [quantile([e["f"][k] for e in es], .5) for k in range(NS)]
        for e in es:
            e["c"] = [e["f"][k] - med[k] for k in range(NS)]


def train(ex, without=None, path="features"):
    """The listener of realism/Listener.cpp on the files of `read`: every source centred on its
    own median, every file (renders included) standardised by the recordings' pooled median and
    IQR / 1.349 (floored), one centroid per (material, source) of the recordings, without the
    source `without` if given. Sets e["c"] and e["z"]; returns (recordings, centroids), the
    centroids as (material, source, z) sorted. Exits naming `path` when `without` recorded
    nothing there."""
    if without is not None and without not in {e["source"] for e in ex
                                                if e["source"] != "synthetic"}:
        sys.exit(f"{path}: no recording of source '{without}'")
    centre_by_source(ex)
    rec = [e for e in ex if e["source"] not in ("synthetic", without)]
    if not rec:
        return rec, []
    centre = [quantile([e["c"][k] for e in rec], .5) for k in range(NS)]
    scale = [max((quantile([e["c"][k] for e in rec], .75) -
                  quantile([e["c"][k] for e in rec], .25)) / 1.349, FLOORS[k])
             for k in range(NS)]
    for e in ex:
        e["z"] = [(e["c"][k] - centre[k]) / scale[k] for k in range(NS)]
    cents = []
    for m, s in sorted({(e["material"], e["source"]) for e in rec}):
        zs = [e["z"] for e in rec if e["material"] == m and e["source"] == s]
        cents.append((m, s, [quantile([v[k] for v in zs], .5) for k in range(NS)]))
    return rec, cents


def category_of_render(e):
    if e["material"] in CATEGORY:
        return CATEGORY[e["material"]]
    return SURFACE_CATEGORY.get(e["name"], "?")


def parse_args(argv, usage):
    """The command line shared with material_spread.py: FEATURES.csv [--without SOURCE] [NAME ...].
    Returns (without or None, the positional arguments, the other --flags); exits with `usage`
    when no features file is given."""
    without = None
    if "--without" in argv:
        i = argv.index("--without")
        if i + 1 >= len(argv):
            sys.exit("--without needs a source name")
        without = argv[i + 1]
        argv = argv[:i] + argv[i + 2:]
    args = [a for a in argv[1:] if not a.startswith("--")]
    if not args:
        sys.exit(usage)
    return without, args, [a for a in argv[1:] if a.startswith("--")]


def main(argv):
    without, args, flags = parse_args(argv, __doc__)
    show_all = "--all" in flags
    only = set(args[1:])
    ex = read(args[0])
    rec, cents = train(ex, without, args[0])
    syn = [e for e in ex if e["source"] == "synthetic"]
    if not rec or not syn:
        sys.exit(f"{args[0]}: needs recordings and renders (source 'synthetic')")
    by_cat = {}
    for e in rec:
        by_cat.setdefault(CATEGORY[e["material"]], []).append(e["z"])
    wrong = 0
    pull = [0.0] * NS
    for e in syn:
        if only and e["name"] not in only:
            continue
        cat = category_of_render(e)
        ds = sorted(((sum((e["z"][k] - c[k]) ** 2 for k in range(NS)), m, s, c)
                     for m, s, c in cents), key=lambda t: t[0])
        heard = ds[0]
        own = next(t for t in ds if CATEGORY[t[1]] == cat)
        heard_cat = CATEGORY[heard[1]]
        if heard_cat != cat:
            wrong += 1
        elif not show_all and not only:
            continue
        print(f"\n{e['name']} ({cat}): heard {heard[1]} ({heard[2]}, {heard_cat}) at "
              f"{math.sqrt(heard[0]):.2f}; nearest {cat}: {own[1]} ({own[2]}) at "
              f"{math.sqrt(own[0]):.2f}")
        cz = by_cat[cat]
        print(f"  {'descriptor':<18} {'render':>7} {cat + ' median':>17} {'IQR':>15}  "
              f"{'heard':>6} {'own':>6} {'pull to heard':>13}")
        for k in range(NS):
            p = (e["z"][k] - own[3][k]) ** 2 - (e["z"][k] - heard[3][k]) ** 2
            if heard_cat != cat:
                pull[k] += p
            v = [x[k] for x in cz]
            q1, q2, q3 = quantile(v, .25), quantile(v, .5), quantile(v, .75)
            flag = "<" if e["z"][k] < q1 else (">" if e["z"][k] > q3 else " ")
            print(f"  {KEYS[k]:<18} {e['z'][k]:7.2f} {q2:17.2f} {q1:7.2f}..{q3:6.2f} {flag} "
                  f"{heard[3][k]:6.2f} {own[3][k]:6.2f} {p:13.2f}")
    if not only:
        print(f"\n{wrong} of {len(syn)} renders heard in another category")
        if wrong:
            print("pull towards the wrong category, summed over those renders (z^2):")
            for k in sorted(range(NS), key=lambda k: -pull[k]):
                print(f"  {KEYS[k]:<18} {pull[k]:8.2f}")


if __name__ == "__main__":
    main(sys.argv)
