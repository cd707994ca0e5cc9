#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Coefficients of frictionCosHalfPi (engine/models/Friction.h).

cos(pi t / 2) for |t| <= 1 as Q(t^2): Q is the degree-8 Chebyshev interpolant of
cos(pi sqrt(u) / 2) on [0, 1], computed in 60-digit decimal arithmetic and rounded to double.
Prints the coefficients of u^0 .. u^8 and the largest error of the double evaluation (Estrin's
scheme, exactly as in Friction.h; Python floats are IEEE doubles without FMA) against the decimal
cosine on 8001 points of [-1, 1]. Python standard library only.

    python3 tools/perf/friction_cos_fit.py
"""
from decimal import Decimal, getcontext
from math import comb

getcontext().prec = 60
PI = Decimal("3.14159265358979323846264338327950288419716939937510582097494")
DEGREE = 8


def cos_decimal(x):
    total, term, k = Decimal(0), Decimal(1), 0
    while abs(term) > Decimal(10) ** -58:
        total += term
        k += 2
        term = -term * x * x / (Decimal(k - 1) * Decimal(k))
    return total


def chebyshev_t(k):
    """Monomial coefficients (in x) of the Chebyshev polynomial T_k."""
    prev, cur = [Decimal(1)], [Decimal(0), Decimal(1)]
    if k == 0:
        return prev
    for _ in range(k - 1):
        nxt = [Decimal(0)] + [2 * c for c in cur]
        for i, c in enumerate(prev):
            nxt[i] -= c
        prev, cur = cur, nxt
    return cur


def fit():
    n = DEGREE + 1
    nodes = [cos_decimal(PI * Decimal(2 * j + 1) / Decimal(2 * n)) for j in range(n)]
    values = [cos_decimal(PI * ((x + 1) / 2).sqrt() / 2) for x in nodes]
    polys = [chebyshev_t(k) for k in range(n)]

    def t_at(k, x):
        return sum(c * x**i for i, c in enumerate(polys[k]))

    cheb = [Decimal(2) / n * sum(values[j] * t_at(k, nodes[j]) for j in range(n)) for k in range(n)]
    cheb[0] /= 2
    in_x = [Decimal(0)] * n
    for k in range(n):
        for i, c in enumerate(polys[k]):
            in_x[i] += cheb[k] * c
    in_u = [Decimal(0)] * n  # x = 2 u - 1
    for i in range(n):
        for j in range(i + 1):
            in_u[j] += in_x[i] * comb(i, j) * Decimal(2) ** j * Decimal(-1) ** (i - j)
    return [float(c) for c in in_u]


def evaluate(c, t):
    u = t * t
    u2 = u * u
    u4 = u2 * u2
    q01 = c[0] + c[1] * u
    q23 = c[2] + c[3] * u
    q45 = c[4] + c[5] * u
    q67 = c[6] + c[7] * u
    return (q01 + q23 * u2) + ((q45 + q67 * u2) + c[8] * u4) * u4


def main():
    c = fit()
    for k, v in enumerate(c):
        print(f"u^{k}: {v!r}")
    worst = max(abs(Decimal(evaluate(c, i / 4000)) - cos_decimal(PI * Decimal(i / 4000) / 2))
                for i in range(-4000, 4001))
    print(f"largest error of the double evaluation: {float(worst):.3g}")


if __name__ == "__main__":
    main()
