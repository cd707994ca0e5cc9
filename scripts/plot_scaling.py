#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Plots `underfoot bench --only scaling` (its Markdown table on stdin) as an SVG on stdout:
one panel per axis (voices, modes per voice, grain events/s), ns per output sample against the
axis value on linear scales, the measured points joined by lines.

    underfoot bench --only scaling | python3 scripts/plot_scaling.py > docs/scaling.svg
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


def main():
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
