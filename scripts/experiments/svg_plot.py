"""Helper module: a per-view line figure as SVG, for the analysis scripts beside it.

No plotting library on the project's machines: the C++ side draws its PNGs with OpenCV, these
scripts write SVG text. One panel per row; each panel has polylines (NaN breaks a line), faint vertical
marks (the test views, say) and a strip of ticks under the axis per named series (the views
each method held, with the fraction of seeds as opacity). Written atomically."""
import math
import os

COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b"]


def _esc(text):
    return str(text).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def _ticks(lo, hi, n=5):
    """About n round tick values in [lo, hi]."""
    span = hi - lo
    if not span > 0:
        return [lo]
    step = 10 ** math.floor(math.log10(span / n))
    for m in (1, 2, 5, 10):
        if span / (step * m) <= n:
            step *= m
            break
    first = math.ceil(lo / step) * step
    return [first + k * step for k in range(int((hi - first) / step + 1e-9) + 1)]


def panelSvg(panel, x0, y0, w, h):
    """One panel's SVG elements. panel: dict with title, xlabel, ylabel, n (x runs 0..n-1),
    series [(label, ys)], marks [x], strips [(label, {x: weight in (0, 1]})]."""
    out = []
    left, right, top = 64, 10, 22
    strip_h = 9 * len(panel.get("strips", []))
    bottom = 34 + strip_h
    pw, ph = w - left - right, h - top - bottom
    vals = [v for _, ys in panel["series"] for v in ys if v == v and math.isfinite(v)]
    lo, hi = (min(vals), max(vals)) if vals else (0.0, 1.0)
    pad = 0.04 * (hi - lo or 1.0)
    lo, hi = lo - pad, hi + pad
    n = panel["n"]
    sx = lambda x: x0 + left + pw * (x / max(n - 1, 1))
    sy = lambda y: y0 + top + ph * (1.0 - (y - lo) / (hi - lo))
    out.append(f'<text x="{x0 + left}" y="{y0 + 15}" font-size="13" font-weight="bold">{_esc(panel["title"])}</text>')
    for m in panel.get("marks", []):
        out.append(f'<line x1="{sx(m):.1f}" y1="{y0 + top}" x2="{sx(m):.1f}" y2="{y0 + top + ph}" '
                   'stroke="#bbbbbb" stroke-width="1" stroke-dasharray="2,2"/>')
    for t in _ticks(lo, hi):
        out.append(f'<line x1="{x0 + left - 4}" y1="{sy(t):.1f}" x2="{x0 + left + pw}" y2="{sy(t):.1f}" '
                   'stroke="#eeeeee"/>')
        out.append(f'<text x="{x0 + left - 6}" y="{sy(t) + 4:.1f}" font-size="10" text-anchor="end">{t:g}</text>')
    for t in _ticks(0, n - 1, 10):
        out.append(f'<text x="{sx(t):.1f}" y="{y0 + top + ph + 12}" font-size="10" text-anchor="middle">{t:g}</text>')
    out.append(f'<rect x="{x0 + left}" y="{y0 + top}" width="{pw}" height="{ph}" fill="none" stroke="#444444"/>')
    out.append(f'<text x="{x0 + 12}" y="{y0 + top + ph / 2:.1f}" font-size="11" text-anchor="middle" '
               f'transform="rotate(-90 {x0 + 12} {y0 + top + ph / 2:.1f})">{_esc(panel["ylabel"])}</text>')
    for k, (label, ys) in enumerate(panel["series"]):
        colour = COLOURS[k % len(COLOURS)]
        run = []
        for x, y in enumerate(list(ys) + [float("nan")]):
            if y == y and math.isfinite(y):
                run.append(f"{sx(x):.1f},{sy(y):.1f}")
                continue
            if len(run) > 1:
                out.append(f'<polyline points="{" ".join(run)}" fill="none" stroke="{colour}" stroke-width="1.4"/>')
            elif run:
                out.append(f'<circle cx="{run[0].split(",")[0]}" cy="{run[0].split(",")[1]}" r="1.6" fill="{colour}"/>')
            run = []
        lx = x0 + left + 8 + 120 * k
        out.append(f'<line x1="{lx}" y1="{y0 + top + 10}" x2="{lx + 16}" y2="{y0 + top + 10}" stroke="{colour}" '
                   'stroke-width="2"/>')
        out.append(f'<text x="{lx + 20}" y="{y0 + top + 14}" font-size="11">{_esc(label)}</text>')
    for k, (label, weights) in enumerate(panel.get("strips", [])):
        colour = COLOURS[k % len(COLOURS)]
        yy = y0 + top + ph + 17 + 9 * k
        for x, wgt in sorted(weights.items()):
            out.append(f'<rect x="{sx(x) - 1.5:.1f}" y="{yy}" width="3" height="7" fill="{colour}" '
                       f'fill-opacity="{max(0.08, min(1.0, wgt)):.2f}"/>')
        out.append(f'<text x="{x0 + left - 6}" y="{yy + 7}" font-size="9" text-anchor="end">{_esc(label)}</text>')
    out.append(f'<text x="{x0 + left + pw / 2:.1f}" y="{y0 + h - 4}" font-size="11" text-anchor="middle">'
               f'{_esc(panel["xlabel"])}</text>')
    return out


def writeSvg(path, panels, caption="", width=1100, panel_h=300):
    """Panels stacked top to bottom, an optional caption line on top; written to a
    temporary name, then renamed."""
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    with open(path + ".tmp", "w") as fh:
        fh.write(svgText(panels, caption, width, panel_h))
    os.replace(path + ".tmp", path)


def svgText(panels, caption="", width=1100, panel_h=300):
    """writeSvg's file text (for a script that compares it with a committed file)."""
    head = 24 if caption else 0
    height = head + panel_h * len(panels)
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
             f'font-family="sans-serif"><rect width="{width}" height="{height}" fill="white"/>']
    if caption:
        parts.append(f'<text x="10" y="16" font-size="12">{_esc(caption)}</text>')
    for i, p in enumerate(panels):
        parts += panelSvg(p, 0, head + i * panel_h, width, panel_h)
    parts.append("</svg>")
    return "\n".join(parts) + "\n"
