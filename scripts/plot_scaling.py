#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Plots `underfoot bench --only scaling` (its Markdown table on stdin) as an SVG on stdout:
one panel per axis (voices, modes per voice, grain events/s), ns per output sample against the
axis value on linear scales, the measured points joined by lines.

    underfoot bench --only scaling | python3 scripts/plot_scaling.py > docs/scaling.svg

With --pareto it reads `underfoot bench --only impact` instead and plots every impact setting's
spectral distance to the reference against its ns per sample, the Pareto front (no other setting
both cheaper and more accurate) joined by a line:

    underfoot bench --only impact | python3 scripts/plot_scaling.py --pareto > docs/pareto.svg
"""
import sys


def read_points(lines):
    points = {}
    for line in lines:
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 4 or not cells[1].isdigit():
            continue
        points.setdefault(cells[0], []).append((float(cells[1]), float(cells[2])))
    return points


def panel(x0, title, pts, w=300, h=220):
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    xmax, ymax = max(xs) * 1.05, max(ys) * 1.1
    sx = lambda x: x0 + 50 + (w - 60) * x / xmax
    sy = lambda y: 30 + (h - 70) * (1 - y / ymax)
    out = [f'<text x="{x0 + w / 2}" y="18" text-anchor="middle" font-size="13">{title}</text>',
           f'<line x1="{sx(0)}" y1="{sy(0)}" x2="{sx(xmax)}" y2="{sy(0)}" stroke="black"/>',
           f'<line x1="{sx(0)}" y1="{sy(0)}" x2="{sx(0)}" y2="{sy(ymax)}" stroke="black"/>',
           f'<text x="{x0 + w / 2}" y="{h - 8}" text-anchor="middle" font-size="11">{title}</text>',
           f'<text x="{x0 + 12}" y="{sy(ymax / 2)}" font-size="11" transform="rotate(-90 '
           f'{x0 + 12} {sy(ymax / 2)})" text-anchor="middle">ns / sample</text>']
    for k in range(5):
        y = ymax * k / 4
        out.append(f'<text x="{sx(0) - 4}" y="{sy(y) + 4}" font-size="9" '
                   f'text-anchor="end">{y:.0f}</text>')
        x = xmax * k / 4
        out.append(f'<text x="{sx(x)}" y="{sy(0) + 13}" font-size="9" '
                   f'text-anchor="middle">{x:.0f}</text>')
    path = " ".join(f"{sx(x):.1f},{sy(y):.1f}" for x, y in pts)
    out.append(f'<polyline points="{path}" fill="none" stroke="#1f77b4" stroke-width="1.5"/>')
    for x, y in pts:
        out.append(f'<circle cx="{sx(x):.1f}" cy="{sy(y):.1f}" r="2.5" fill="#1f77b4"/>')
    return out


def pareto(lines):
    pts = []
    for line in lines:
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 9 or not cells[5].endswith("dB"):
            continue
        pts.append((cells[0], float(cells[6]), float(cells[5].split()[0])))
    if not pts:
        sys.exit("plot_scaling.py --pareto: no impact rows (| setting | ... | spectral distance "
                 "| ns/sample | ...) on stdin")
    front = sorted((p for p in pts if not any(q[1] <= p[1] and q[2] <= p[2] and
                                              (q[1] < p[1] or q[2] < p[2]) for q in pts)),
                   key=lambda p: p[1])
    w, h = 640, 420
    xmax = max(p[1] for p in pts) * 1.08
    ymax = max(p[2] for p in pts) * 1.1
    sx = lambda x: 60 + (w - 80) * x / xmax
    sy = lambda y: 20 + (h - 70) * (1 - y / ymax)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
           f'font-family="sans-serif">',
           f'<line x1="{sx(0)}" y1="{sy(0)}" x2="{sx(xmax)}" y2="{sy(0)}" stroke="black"/>',
           f'<line x1="{sx(0)}" y1="{sy(0)}" x2="{sx(0)}" y2="{sy(ymax)}" stroke="black"/>',
           f'<text x="{w / 2}" y="{h - 10}" text-anchor="middle" font-size="12">ns per sample '
           f'(3-mode impact, 4 strikes/s)</text>',
           f'<text x="14" y="{h / 2}" font-size="12" transform="rotate(-90 14 {h / 2})" '
           f'text-anchor="middle">spectral distance to the 8x reference, dB</text>']
    for k in range(5):
        out.append(f'<text x="{sx(0) - 4}" y="{sy(ymax * k / 4) + 4}" font-size="10" '
                   f'text-anchor="end">{ymax * k / 4:.2f}</text>')
        out.append(f'<text x="{sx(xmax * k / 4)}" y="{sy(0) + 14}" font-size="10" '
                   f'text-anchor="middle">{xmax * k / 4:.0f}</text>')
    path = " ".join(f"{sx(p[1]):.1f},{sy(p[2]):.1f}" for p in front)
    out.append(f'<polyline points="{path}" fill="none" stroke="#d62728" stroke-width="1.5"/>')
    for name, x, y in pts:
        colour = "#d62728" if (name, x, y) in front else "#1f77b4"
        out.append(f'<circle cx="{sx(x):.1f}" cy="{sy(y):.1f}" r="3" fill="{colour}"/>')
        out.append(f'<text x="{sx(x) + 5:.1f}" y="{sy(y) - 4:.1f}" font-size="8">'
                   f'{name.replace("&", "&amp;")}</text>')
    out.append("</svg>")
    print("\n".join(out))


def main():
    if "--pareto" in sys.argv[1:]:
        pareto(sys.stdin)
        return
    points = read_points(sys.stdin)
    if not points:
        sys.exit("plot_scaling.py: no '| axis | value | ns/sample | per unit |' rows on stdin")
    body = []
    for i, (axis, pts) in enumerate(points.items()):
        body += panel(10 + 310 * i, axis, pts)
    width = 20 + 310 * len(points)
    print(f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="230" '
          f'font-family="sans-serif">')
    print("\n".join(body))
    print("</svg>")


if __name__ == "__main__":
    main()
