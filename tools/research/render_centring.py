#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Centre the renders on the held-out source's mix of materials? A test of the listener's render
side (docs/decisions/held-out-recordings-bar.md, "Changing the listener").

    underfoot compare --listener --seed N --features fN.csv      (for N in 3 7 11)
    python3 tools/research/render_centring.py f3.csv f7.csv f11.csv

The nested listener of `underfoot compare --listener` (realism/Listener.cpp) centres every source
on its own per-feature median, the renders (source "synthetic") as one source. A held-out source
recorded only some materials, so its median is the median of that mix, while the renders' median
is that of every bundled surface. This script rebuilds the nested listener and judges the renders
of each held-out source's materials three ways:

  shipped   the renders centred on the median of every render (as realism/Listener.cpp does);
  subset    on the median of the renders of the materials the held-out source recorded;
  weighted  the same, each material weighted by the held-out source's number of files of it.

It prints category and material right, summed over the files given (one per render seed); the
first row reproduces the "nested" totals of `underfoot compare --figures`. Pure Python.
"""
import collections
import sys

from category_why import read
from listener_common import CATEGORY, FLOORS, NS, quantile


def weighted_median(values, weights):
    """The lowest value at which the cumulative weight reaches half the total."""
    pairs = sorted(zip(values, weights))
    total, acc = sum(weights), 0.0
    for v, w in pairs:
        acc += w
        if acc >= total / 2 - 1e-12:
            return v
    return pairs[-1][0]


def centred(rows, ref, weights=None):
    if weights is None:
        med = [quantile([e["f"][k] for e in ref], .5) for k in range(NS)]
    else:
        med = [weighted_median([e["f"][k] for e in ref], [weights[e["material"]] for e in ref])
               for k in range(NS)]
    return [[e["f"][k] - med[k] for k in range(NS)] for e in rows]


def nearest_material(train):
    """The listener trained on (centred features, source, material): a function of a centred
    feature vector that returns the material of the nearest (source, material) centroid."""
    feats = [c for c, _, _ in train]
    cen = [quantile([c[k] for c in feats], .5) for k in range(NS)]
    scale = [max((quantile([c[k] for c in feats], .75) - quantile([c[k] for c in feats], .25))
                 / 1.349, FLOORS[k]) for k in range(NS)]

    def z(c):
        return [(c[k] - cen[k]) / scale[k] for k in range(NS)]

    groups = collections.defaultdict(list)
    for c, s, m in train:
        groups[(s, m)].append(z(c))
    cents = [(m, [quantile([v[k] for v in zs], .5) for k in range(NS)])
             for (_, m), zs in groups.items()]

    def classify(c):
        zc = z(c)
        return min(cents, key=lambda t: sum((zc[k] - t[1][k]) ** 2 for k in range(NS)))[0]
    return classify


def score(path, mode):
    ex = read(path)
    rec = [e for e in ex if e["source"] != "synthetic"]
    syn = [e for e in ex if e["source"] == "synthetic"]
    for s in {e["source"] for e in rec}:
        es = [e for e in rec if e["source"] == s]
        for e, c in zip(es, centred(es, es)):
            e["c"] = c
    n = cat = mat = 0
    for held in sorted({e["source"] for e in rec}):
        classify = nearest_material([(e["c"], e["source"], e["material"]) for e in rec
                                     if e["source"] != held])
        files = collections.Counter(e["material"] for e in rec if e["source"] == held)
        judged = [e for e in syn if e["material"] in files]
        if mode == "shipped":
            cs = centred(syn, syn)
        elif mode == "subset":
            cs = centred(syn, judged)
        else:
            surfaces = collections.Counter(e["material"] for e in judged)
            cs = centred(syn, judged, {m: files[m] / surfaces[m] for m in surfaces})
        for e, c in zip(syn, cs):
            if e["material"] in files:
                heard = classify(c)
                n += 1
                cat += CATEGORY[heard] == CATEGORY[e["material"]]
                mat += heard == e["material"]
    return n, cat, mat


def main(paths):
    if not paths:
        sys.exit(__doc__)
    for mode in ("shipped", "subset", "weighted"):
        t = [sum(x) for x in zip(*(score(p, mode) for p in paths))]
        print(f"{mode:9} category {t[1]}/{t[0]}  material {t[2]}/{t[0]}")


if __name__ == "__main__":
    main(sys.argv[1:])
