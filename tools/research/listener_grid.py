#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""How the listener's configuration was chosen (docs/explanation/realism.md, "The listener").

    underfoot compare --listener --features features.csv
    python3 tools/research/listener_grid.py features.csv [--by-category]

Reads the per-file listener features written by `compare --features` and evaluates, leave-one-
source-out on the recordings only, a small fixed grid: feature set (all, scalar descriptors
only, scalars + third-octave bands from 200 Hz), centring (none, each source on its own median,
each source standardised by its own median and spread, each source on its own median with the
sources of one material left out of training: centring puts their one material at the origin;
each source on its own median but those of one material, centred on the pooled median of the
training sources that recorded several)
and classifier (one centroid per
material, one per source and material, 3 nearest neighbours). Same scaling as realism/
Listener.cpp (training set median and IQR / 1.349 with the descriptors' floors).

Choosing the best cell of that grid on the same held-out sources flatters it, so the script
also prints a nested estimate: for each held-out source the configuration is chosen by a
leave-one-source-out run on the other sources only, then scored on the held-out one.
The inner choice takes the configuration with the most materials right (with --by-category:
the most categories right, then materials, as the onset listener's grid does, so the two
nested estimates can be compared like for like). The onset listener's grid (onset features,
realism/OnsetListener.h) is evaluated in C++: `underfoot compare --listener --onset-listener
--listener-grid`.
Pure Python (no numpy), a few seconds.
"""
import csv
import math
import sys

from listener_common import CATEGORY, FLOORS, NS, quantile


def spread(v, k):
    return max((quantile(v, .75) - quantile(v, .25)) / 1.349, FLOORS[k] if k < NS else 1.0)


def centre(examples, mode, held=None):
    if mode == "none":
        return examples
    if mode == "c-multi":
        mode = "c"
    mats_of = {}
    for e in examples:
        mats_of.setdefault(e[1], set()).add(e[2])
    n = len(examples[0][3])
    if mode == "c-pool1":
        # the pooled median of the raw features of the training sources that recorded several
        # materials (the held-out one excluded: it must not shape the training)
        pool = [e for e in examples if len(mats_of[e[1]]) > 1 and e[1] != held]
        pooled = [quantile([e[3][k] for e in pool], .5) for k in range(n)]
    out = []
    for s in sorted({e[1] for e in examples}):
        es = [e for e in examples if e[1] == s]
        if mode == "c-pool1" and len(mats_of[s]) == 1 and s != held:
            med = pooled
        else:
            med = [quantile([e[3][k] for e in es], .5) for k in range(n)]
        sc = [spread([e[3][k] for e in es], k) if mode == "z" else 1.0 for k in range(n)]
        out += [(e[0], e[1], e[2], [(e[3][k] - med[k]) / sc[k] for k in range(n)]) for e in es]
    return out


def scaling(train, feats):
    n = len(train[0][3])
    sc = [spread([e[3][k] for e in train], k) for k in range(n)]
    nb = sum(k >= NS for k in feats)
    ns = sum(k < NS for k in feats)
    w = [math.sqrt(ns / nb) if (k >= NS and nb and ns) else 1.0 for k in range(n)]
    return sc, w


def dist(a, b, m, feats):
    sc, w = m
    return math.sqrt(sum(((a[k] - b[k]) / sc[k] * w[k]) ** 2 for k in feats))


def classify(m, train, x, feats, method):
    if method in ("centroid", "source-centroid"):
        groups = {(e[2], e[1] if method == "source-centroid" else "") for e in train}
        best = None
        for mat, src in sorted(groups):
            es = [e for e in train if e[2] == mat and (not src or e[1] == src)]
            c = [quantile([e[3][j] for e in es], .5) for j in range(len(x))]
            d = dist(x, c, m, feats)
            if best is None or d < best[0]:
                best = (d, mat)
        return best[1]
    near = sorted((dist(x, e[3], m, feats), e[2]) for e in train)[:3]
    votes = {}
    for i, (_, mat) in enumerate(near):
        votes[mat] = votes.get(mat, 0) + 1 / (1 + 0.01 * i)
    return max(votes, key=votes.get)


def loso(examples, feats, mode, method, only=None):
    # c-pool1's centring depends on the held-out source: centred per source in the loop
    ex = centre(examples, mode) if mode != "c-pool1" else None
    mc = cc = n = 0
    for held in sorted({e[1] for e in examples}):
        if only and held != only:
            continue
        if mode == "c-pool1":
            ex = centre(examples, mode, held)
        train = [e for e in ex if e[1] != held]
        if mode == "c-multi":
            mats_of = {}
            for e in train:
                mats_of.setdefault(e[1], set()).add(e[2])
            train = [e for e in train if len(mats_of[e[1]]) > 1]
        m = scaling(train, feats)
        mats = {e[2] for e in train}
        for e in ex:
            if e[1] != held or e[2] not in mats:
                continue
            p = classify(m, train, e[3], feats, method)
            n += 1
            mc += p == e[2]
            cc += CATEGORY[p] == CATEGORY[e[2]]
    return mc, cc, n


def main():
    by_category = "--by-category" in sys.argv[2:]
    rows = list(csv.reader(open(sys.argv[1])))
    header, data = rows[0], rows[1:]
    rec = [(r[0], r[1], r[2], [float(v) for v in r[3:]]) for r in data if r[1] != "synthetic"]
    nf = len(rec[0][3])
    sets = {"all": list(range(nf)), "scalars": list(range(NS)),
            "scalars+bands>=200Hz": list(range(NS)) +
            [k for k in range(NS, nf) if float(header[3 + k][2:]) >= 200]}
    centrings = ("none", "centre", "z", "centre-multi", "centre-pool1")
    grid = [(f, c, m) for f in sets for c in centrings
            for m in ("centroid", "source-centroid", "3-nn")]
    method = {"centroid": "centroid", "source-centroid": "source-centroid", "3-nn": "knn"}
    mode = {"none": "none", "centre": "c", "z": "z", "centre-multi": "c-multi",
            "centre-pool1": "c-pool1"}
    print(f"{len(rec)} recordings from {len({e[1] for e in rec})} sources")
    print(f"{'features':22} {'centring':12} {'classifier':16} material  category")
    for f, c, m in grid:
        mc, cc, n = loso(rec, sets[f], mode[c], method[m])
        print(f"{f:22} {c:12} {m:16} {mc:3}/{n}    {cc:3}/{n}")
    tot = [0, 0, 0]
    for held in sorted({e[1] for e in rec}):
        inner = [e for e in rec if e[1] != held]
        def score(g):
            mc, cc, _ = loso(inner, sets[g[0]], mode[g[1]], method[g[2]])
            return (cc, mc) if by_category else mc
        f, c, m = max(grid, key=score)
        mc, cc, n = loso(rec, sets[f], mode[c], method[m], only=held)
        print(f"nested: held out {held}: chose {f}/{c}/{m} on the others -> "
              f"material {mc}/{n}, category {cc}/{n}")
        tot = [tot[0] + mc, tot[1] + cc, tot[2] + n]
    print(f"nested estimate: material {tot[0]}/{tot[2]}, category {tot[1]}/{tot[2]}")


if __name__ == "__main__":
    main()
