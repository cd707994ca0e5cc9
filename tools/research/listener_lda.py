#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""A check that was not shipped (docs/explanation/realism.md, "The listener"): does a trained linear
classifier beat the nearest-centroid listeners on unseen sources?

    underfoot compare --listener --onset-listener --features steps.csv
    python3 tools/research/listener_lda.py steps.csv

Reads every step's features (the 14 scalar descriptors, then the onset features), takes each
file's per-feature median, centres every source on its own median (as the listeners do) and
runs leave-one-source-out with a shrinkage linear discriminant: class means (per material, or
per source and material) and the pooled within-class covariance shrunk towards its diagonal,
S = (1 - lambda) S + lambda diag(S); a file goes to the class of smallest Mahalanobis distance.
Also a category-only variant (classes = solid / aggregate / liquid). Every cell is scored on the
held-out sources it was chosen on: the figures flatter it (no nesting). Pure Python, seconds.
"""
import csv
import math
import sys

from listener_common import CATEGORY, NS, quantile


def inverse(a):
    n = len(a)
    m = [row[:] + [1.0 if i == j else 0.0 for j in range(n)] for i, row in enumerate(a)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        pv = m[c][c]
        m[c] = [v / pv for v in m[c]]
        for r in range(n):
            if r != c and m[r][c] != 0:
                f = m[r][c]
                m[r] = [x - f * y for x, y in zip(m[r], m[c])]
    return [row[n:] for row in m]


def lda_loso(files, feats, lam, label, per_source):
    right = n = 0
    cat_right = 0
    for held in sorted({f[1] for f in files}):
        train = [f for f in files if f[1] != held]
        mats = {f[2] for f in train}
        groups = {}
        for f in train:
            groups.setdefault((label(f), f[1] if per_source else ""), []).append(
                [f[3][k] for k in feats])
        means = {g: [sum(c) / len(v) for c in zip(*v)] for g, v in groups.items()}
        d = len(feats)
        s = [[0.0] * d for _ in range(d)]
        for g, v in groups.items():
            for x in v:
                r = [a - b for a, b in zip(x, means[g])]
                for i in range(d):
                    for j in range(d):
                        s[i][j] += r[i] * r[j]
        dof = max(len(train) - len(groups), 1)
        s = [[(1 - lam) * s[i][j] / dof + (lam * s[i][i] / dof if i == j else 0.0)
              for j in range(d)] for i in range(d)]
        si = inverse(s)
        for f in files:
            if f[1] != held or f[2] not in mats:
                continue
            x = [f[3][k] for k in feats]

            def m2(mu):
                r = [a - b for a, b in zip(x, mu)]
                return sum(r[i] * sum(si[i][j] * r[j] for j in range(d)) for i in range(d))
            p = min(means, key=lambda g: m2(means[g]))[0]
            n += 1
            right += p == label(f)
            cat_right += (CATEGORY.get(p, p) == CATEGORY[f[2]])
    return right, cat_right, n


def main():
    rows = list(csv.reader(open(sys.argv[1])))
    header = rows[0][4:]
    steps = {}
    for r in rows[1:]:
        steps.setdefault(r[0], (r[1], r[2], []))[2].append([float(v) for v in r[4:]])
    files = [(name, s, m, [quantile([st[k] for st in st_], .5) for k in range(len(header))])
             for name, (s, m, st_) in steps.items()]
    centred = []
    for s in sorted({f[1] for f in files}):
        fs = [f for f in files if f[1] == s]
        med = [quantile([f[3][k] for f in fs], .5) for k in range(len(header))]
        centred += [(f[0], f[1], f[2], [f[3][k] - med[k] for k in range(len(header))])
                    for f in fs]
    sets = {"scalars": list(range(NS)), "onset": list(range(NS, len(header))),
            "all": list(range(len(header)))}
    print(f"{len(files)} recordings; shrinkage LDA, leave-one-source-out (not nested)")
    print(f"{'features':9} {'lambda':6} {'classes':18} material  category  category-only")
    for name, feats in sets.items():
        for lam in (0.2, 0.5, 0.8, 1.0):
            for per_source in (False, True):
                mr, cr, n = lda_loso(centred, feats, lam, lambda f: f[2], per_source)
                _, co, _ = lda_loso(centred, feats, lam, lambda f: CATEGORY[f[2]], per_source)
                cls = "source x material" if per_source else "material"
                print(f"{name:9} {lam:6} {cls:18} {mr:3}/{n}    {cr:3}/{n}    {co:3}/{n}")


if __name__ == "__main__":
    main()
