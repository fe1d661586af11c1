"""Dependency-free SVG line plots (for ``lindstedt demo``; notebooks use matplotlib)."""

from __future__ import annotations

from typing import Sequence

import numpy as np

__all__ = ["line_plot_svg"]

_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd")


def line_plot_svg(
    curves: Sequence[tuple[np.ndarray, np.ndarray, str]],
    *,
    title: str,
    x_label: str,
    y_label: str,
    log_y: bool = False,
    width: int = 720,
    height: int = 420,
) -> str:
    """An SVG document with one polyline per ``(x, y, label)`` curve, axes, ticks and a legend.

    Examples
    --------
    >>> import numpy as np
    >>> svg = line_plot_svg([(np.arange(3.0), np.arange(3.0), "y = x")], title="t", x_label="x", y_label="y")
    >>> svg.startswith("<svg") and "y = x" in svg
    True
    """
    margin_left, margin_right, margin_top, margin_bottom = 70, 20, 40, 50
    xs = np.concatenate([np.asarray(x, float) for x, _, _ in curves])
    ys = np.concatenate([np.asarray(y, float) for _, y, _ in curves])
    if log_y:
        ys = np.log10(np.maximum(np.abs(ys), 1e-300))
    x_min, x_max = float(xs.min()), float(xs.max())
    y_min, y_max = float(np.nanmin(ys)), float(np.nanmax(ys))
    if y_max == y_min:
        y_max = y_min + 1.0
    if x_max == x_min:
        x_max = x_min + 1.0

    def to_pixels(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        px = margin_left + (x - x_min) / (x_max - x_min) * (width - margin_left - margin_right)
        py = height - margin_bottom - (y - y_min) / (y_max - y_min) * (height - margin_top - margin_bottom)
        return px, py

    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="12">',
        f'<rect width="{width}" height="{height}" fill="white"/>',
        f'<text x="{width / 2}" y="22" text-anchor="middle" font-size="14">{title}</text>',
        f'<line x1="{margin_left}" y1="{height - margin_bottom}" x2="{width - margin_right}" y2="{height - margin_bottom}" stroke="black"/>',
        f'<line x1="{margin_left}" y1="{margin_top}" x2="{margin_left}" y2="{height - margin_bottom}" stroke="black"/>',
        f'<text x="{width / 2}" y="{height - 12}" text-anchor="middle">{x_label}</text>',
        f'<text x="16" y="{height / 2}" text-anchor="middle" transform="rotate(-90 16 {height / 2})">{y_label}{" (log10)" if log_y else ""}</text>',
    ]
    for fraction in np.linspace(0, 1, 5):
        x_value = x_min + fraction * (x_max - x_min)
        y_value = y_min + fraction * (y_max - y_min)
        px, _ = to_pixels(np.array(x_value), np.array(y_min))
        _, py = to_pixels(np.array(x_min), np.array(y_value))
        parts.append(f'<text x="{float(px):.1f}" y="{height - margin_bottom + 16}" text-anchor="middle">{x_value:.3g}</text>')
        parts.append(f'<text x="{margin_left - 6}" y="{float(py) + 4:.1f}" text-anchor="end">{y_value:.3g}</text>')
    for index, (x, y, label) in enumerate(curves):
        y_values = np.log10(np.maximum(np.abs(np.asarray(y, float)), 1e-300)) if log_y else np.asarray(y, float)
        px, py = to_pixels(np.asarray(x, float), y_values)
        points = " ".join(f"{a:.2f},{b:.2f}" for a, b in zip(px, py))
        colour = _COLOURS[index % len(_COLOURS)]
        parts.append(f'<polyline fill="none" stroke="{colour}" stroke-width="1.5" points="{points}"/>')
        legend_y = height - margin_bottom - 10 - 16 * (len(curves) - 1 - index)
        parts.append(f'<text x="{width - margin_right - 10}" y="{legend_y}" text-anchor="end" fill="{colour}">{label}</text>')
    parts.append("</svg>")
    return "\n".join(parts) + "\n"
