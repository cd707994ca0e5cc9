#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Plots `underfoot bench --only scaling` (its Markdown table on stdin) as an SVG on stdout:
one panel per axis (voices, modes per voice, grain events/s), ns per output sample against the
axis value on linear scales, the measured points joined by lines.

    underfoot bench --only scaling | python3 tools/perf/plot_scaling.py > docs/scaling.svg

With --pareto it reads `underfoot bench --only impact` instead and plots every impact setting's
spectral distance to the reference against its ns per sample, the Pareto front (no other setting
both cheaper and more accurate) joined by a line:

    underfoot bench --only impact | python3 tools/perf/plot_scaling.py --pareto > docs/pareto.svg
"""
import math
import sys


def read_points(lines):
    points = {}
    for line in lines:
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 4 or not cells[1].isdigit():
            continue
        points.setdefault(cells[0], []).append((float(cells[1]), float(cells[2])))
    return points


def nice_ticks(vmax, count=5):
    """Round tick values 0, step, 2 step ... covering vmax (step 1, 2 or 5 x 10^k)."""
    raw = vmax / count
    mag = 10 ** math.floor(math.log10(raw))
    step = next(m * mag for m in (1, 2, 5, 10) if m * mag >= raw)
    n = math.ceil(vmax / step - 1e-9)
    return [step * k for k in range(n + 1)]


def fmt(v):
    return f"{v:g}" if v < 1e4 else f"{v:.0f}"


def panel(x0, title, pts, w=300, h=230):
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    xt, yt = nice_ticks(max(xs)), nice_ticks(max(ys))
    xmax, ymax = xt[-1], yt[-1]
    sx = lambda x: x0 + 55 + (w - 70) * x / xmax
    sy = lambda y: 30 + (h - 75) * (1 - y / ymax)
    out = [f'<text x="{x0 + w / 2}" y="18" text-anchor="middle" font-size="13">'
           f'cost against {title}</text>',
           f'<line x1="{sx(0)}" y1="{sy(0)}" x2="{sx(xmax)}" y2="{sy(0)}" stroke="black"/>',
           f'<line x1="{sx(0)}" y1="{sy(0)}" x2="{sx(0)}" y2="{sy(ymax)}" stroke="black"/>',
           f'<text x="{sx(xmax / 2)}" y="{h - 12}" text-anchor="middle" font-size="11">{title}</text>',
           f'<text x="{x0 + 12}" y="{sy(ymax / 2)}" font-size="11" transform="rotate(-90 '
           f'{x0 + 12} {sy(ymax / 2)})" text-anchor="middle">ns per output sample</text>']
    for y in yt:
        out.append(f'<line x1="{sx(0)}" y1="{sy(y):.1f}" x2="{sx(xmax)}" y2="{sy(y):.1f}" '
                   f'stroke="#ddd"/>')
        out.append(f'<text x="{sx(0) - 4}" y="{sy(y) + 4:.1f}" font-size="9" '
                   f'text-anchor="end">{fmt(y)}</text>')
    for x in xt:
        out.append(f'<text x="{sx(x):.1f}" y="{sy(0) + 13}" font-size="9" '
                   f'text-anchor="middle">{fmt(x)}</text>')
    path = " ".join(f"{sx(x):.1f},{sy(y):.1f}" for x, y in pts)
    out.append(f'<polyline points="{path}" fill="none" stroke="#1f77b4" stroke-width="1.5"/>')
    for x, y in pts:
        out.append(f'<circle cx="{sx(x):.1f}" cy="{sy(y):.1f}" r="2.5" fill="#1f77b4">'
                   f'<title>{fmt(x)}: {y:g} ns</title></circle>')
    return out


def pareto(lines):
    """Impact settings: a row has a cell 'X dB' (spectral distance) followed by ns/sample."""
    pts = []
    for line in lines:
        cells = [c.strip().strip("*") for c in line.strip().strip("|").split("|")]
        for i, c in enumerate(cells[1:-1], start=1):
            if c.endswith(" dB"):
                try:
                    pts.append((cells[0], float(cells[i + 1]), float(c.split()[0])))
                except ValueError:
                    pass
                break
    if not pts:
        sys.exit("plot_scaling.py --pareto: no impact rows (| setting | ... | spectral distance "
                 "| ns/sample | ...) on stdin")
    front = sorted((p for p in pts if not any(q[1] <= p[1] and q[2] <= p[2] and
                                              (q[1] < p[1] or q[2] < p[2]) for q in pts)),
                   key=lambda p: p[1])
    # Distances span 0.01 to several dB: a log axis, floored at 0.005 dB (shown as "≤ 0.005").
    floor = 0.005
    ly = lambda d: math.log10(max(d, floor))
    ylo, yhi = math.log10(floor), math.ceil(ly(max(p[2] for p in pts)))
    xt = nice_ticks(max(p[1] for p in pts))
    xmax = xt[-1]
    w, h, plot_w = 900, 430, 520
    sx = lambda x: 70 + plot_w * x / xmax
    sy = lambda d: 20 + (h - 80) * (1 - (ly(d) - ylo) / (yhi - ylo))
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
           f'font-family="sans-serif">',
           f'<line x1="{sx(0)}" y1="{sy(floor)}" x2="{sx(xmax)}" y2="{sy(floor)}" stroke="black"/>',
           f'<line x1="{sx(0)}" y1="{sy(floor)}" x2="{sx(0)}" y2="{sy(10 ** yhi)}" stroke="black"/>',
           f'<text x="{sx(xmax / 2)}" y="{h - 25}" text-anchor="middle" font-size="12">ns per '
           f'output sample (3-mode impact, 4 strikes/s)</text>',
           f'<text x="16" y="{h / 2}" font-size="12" transform="rotate(-90 16 {h / 2})" '
           f'text-anchor="middle">spectral distance to the 8x reference, dB (log)</text>',
           f'<text x="{sx(0)}" y="{h - 6}" font-size="10">red: the Pareto front (no other setting '
           f'both cheaper and closer to the reference)</text>']
    for e in range(int(ylo) - 1, int(yhi) + 1):
        for m in (1, 2, 5):
            d = m * 10.0 ** e
            if d < floor or ly(d) > yhi + 1e-9:
                continue
            label = f"{d:g}" if d > floor else f"≤ {d:g}"
            out.append(f'<line x1="{sx(0)}" y1="{sy(d):.1f}" x2="{sx(xmax)}" y2="{sy(d):.1f}" '
                       f'stroke="#ddd"/>')
            out.append(f'<text x="{sx(0) - 4}" y="{sy(d) + 4:.1f}" font-size="10" '
                       f'text-anchor="end">{label}</text>')
    for x in xt:
        out.append(f'<text x="{sx(x):.1f}" y="{sy(floor) + 14}" font-size="10" '
                   f'text-anchor="middle">{fmt(x)}</text>')
    path = " ".join(f"{sx(p[1]):.1f},{sy(p[2]):.1f}" for p in front)
    out.append(f'<polyline points="{path}" fill="none" stroke="#d62728" stroke-width="1.5"/>')
    # Numbered points; the names go to a legend so that close points stay readable.
    for k, (name, x, y) in enumerate(pts, start=1):
        on_front = (name, x, y) in front
        colour = "#d62728" if on_front else "#1f77b4"
        out.append(f'<circle cx="{sx(x):.1f}" cy="{sy(y):.1f}" r="3.5" fill="{colour}">'
                   f'<title>{name}: {x:g} ns, {y:g} dB</title></circle>')
        out.append(f'<text x="{sx(x) + 5:.1f}" y="{sy(y) - 4 - 9 * (k % 2):.1f}" font-size="9" '
                   f'fill="{colour}">{k}</text>')
        out.append(f'<text x="{sx(xmax) + 25}" y="{30 + 16 * k}" font-size="10" fill="{colour}">'
                   f'{k}. {name.replace("&", "&amp;")}: {x:g} ns, {y:g} dB</text>')
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
