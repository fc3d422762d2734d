"""Figures, with the studies' conventions: log-log axes, slope guides, the source's points beside the measured.

A study declares most of its figures as data, a :class:`Plot` of :class:`Curve` s drawn from the
rows of one of its tables (:func:`draw`), so that every figure can be redrawn from the tables alone.
Figures that need more than a table holds (profiles) use :func:`profile_grid` and :func:`stacked_shares`.
"""

from __future__ import annotations

import json
import math
import textwrap
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

# A panel's title sits at a fixed height above its axes (the ticks are below and left of every panel):
# otherwise matplotlib measures every tick label of every panel to lift the title clear of them, the
# costliest step of drawing a log-log panel.
matplotlib.rcParams["axes.titley"] = 1.0


def profiles(path, x_exact, exact: dict, x_particles, particles: dict, x_nodes=None, nodes: dict | None = None,
             title: str = ""):
    """One panel per field: exact (line), particles (dots), grid nodes (crosses). Saves a PNG; the
    layout is constrained, so the title (lines split by ``\\n``) fits above the panels."""
    names = list(exact)
    width = max(4.2 * len(names), 6.0)
    fig, axes = plt.subplots(1, len(names), figsize=(width, max(3.8, width / MAX_ASPECT)), squeeze=False,
                             layout="constrained")
    for ax, name in zip(axes[0], names, strict=False):
        ax.plot(x_exact, exact[name], "k-", lw=1.2, label="exact")
        if name in particles:
            ax.plot(x_particles, particles[name], ".", ms=2.5, color="tab:blue", label="MPM particles")
        if nodes and name in nodes:
            ax.plot(x_nodes, nodes[name], "x", ms=3, color="tab:red", label="MPM grid nodes")
        ax.set_xlabel("x")
        ax.set_ylabel(name)
    axes[0][0].legend(fontsize=8)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.savefig(path, dpi=120)
    plt.close(fig)


# ----------------------------------------------------------------------------- the studies' conventions

def slope_guides(ax, h, e0: float, slopes=(1, 2)) -> None:
    """Dotted grey lines ``e0 (h / h_max)^k`` over the range of ``h``, one per slope ``k``, labelled."""
    h = np.sort(np.asarray(h, float))
    for k in slopes:
        ax.loglog(h, e0 * (h / h[-1]) ** k, ":", color="gray", lw=0.8)
        ax.annotate(f"slope {k:g}", (h[0], e0 * (h[0] / h[-1]) ** k), fontsize=6, color="gray")


#: The widest figure the report embeds (width : height): readable at a page width of about 900 px.
MAX_ASPECT = 2.5


def grid_shape(n: int, size: tuple[float, float], max_aspect: float = MAX_ASPECT) -> tuple[int, int]:
    """``(rows, columns)`` for ``n`` panels of ``size`` (width, height): the fewest rows whose figure
    is at most ``max_aspect`` wide for its height, and as few columns as those rows need."""
    for ncols in range(max(n, 1), 0, -1):
        nrows = -(-n // ncols)
        if size[0] * ncols <= max_aspect * size[1] * nrows:
            return nrows, -(-n // nrows)  # as few columns as these rows need
    return n, 1


def panels(path, content: dict, xlabel: str, ylabel: str, title: str = "", ncols: int | None = None,
           slopes=(), size=(4.2, 3.8), log: bool = True, legends: bool = False) -> None:
    """One panel per entry of ``content = {panel title: {label: (x, y, fmt, options)}}`` (``options``
    optional: matplotlib keywords), in ``ncols`` columns (one row when not given; never more columns
    than panels), log-log unless ``log`` is false, with slope guides through the
    largest value of each panel and the legend in the first one. The source's points are a series
    like any other, drawn black and open (fmt ``"ks"``/``"ko"``/``"k*"``, ``mfc="none"``). With
    ``legends`` every panel gets its own legend (panels that show different series)."""
    names = list(content)
    widest = grid_shape(len(names), size)[1]
    ncols = min(ncols or widest, widest)
    nrows = -(-len(names) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(size[0] * ncols, size[1] * nrows), squeeze=False)
    for ax, name in zip(axes.ravel(), names, strict=False):
        xs, top = [], 0.0
        for label, (x, y, fmt, *options) in content[name].items():
            y = np.asarray(y, float)
            style = {"ms": 3.5, "lw": 1.1, **(options[0] if options else {})}
            (ax.loglog if log else ax.plot)(x, y, fmt, label=label, **style)
            xs += list(x)
            top = max(top, np.nanmax(y, initial=0.0))
        if slopes and top > 0:
            slope_guides(ax, xs, top * 1.3, slopes)
        if log:  # minor ticks at 2 and 5 of each decade, not 2 ... 9: a third of the ticks to lay out
            for axis in (ax.xaxis, ax.yaxis):
                axis.set_minor_locator(matplotlib.ticker.LogLocator(subs=(2.0, 5.0)))
        ax.set_title(name, fontsize=9)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        if legends:
            ax.legend(fontsize=6, markerscale=1.5)
    for ax in axes.ravel()[len(names):]:
        ax.set_visible(False)
    axes[0][0].legend(fontsize=6, markerscale=1.5)
    wrapped = textwrap.fill(title, max(int(fig.get_size_inches()[0] * CHARACTERS_PER_INCH), 20)) if title else ""
    fixed_margins(fig, wrapped.count("\n") + 1 if title else 0)
    save(fig, path, wrapped, caption=title, layout=False)


#: The margins of a grid of panels, inches: left (tick labels and the y label), right, bottom (tick
#: labels and the x label), top (a panel title; each line of a figure title adds TITLE_MARGIN), between panels.
MARGINS = dict(left=0.8, right=0.2, bottom=0.6, top=0.35, between_x=0.9, between_y=0.85)
TITLE_MARGIN = 0.2
#: A figure title (9 points) is wrapped at this many characters per inch of the figure's width.
CHARACTERS_PER_INCH = 13


def fixed_margins(fig, title_lines: int) -> None:
    """Lay out ``fig``'s grid of panels with the fixed :data:`MARGINS` and room for a figure title of
    ``title_lines`` lines: the layout ``tight_layout`` gives panels with short labels, without measuring
    every tick label (which costs about half of the drawing time of a log-log figure)."""
    width, height = fig.get_size_inches()
    nrows, ncols = fig.axes[0].get_subplotspec().get_gridspec().get_geometry()
    m = MARGINS
    top = m["top"] + TITLE_MARGIN * title_lines + (0.1 if title_lines else 0.0)
    # subplots_adjust's spaces are fractions of a panel's width (height): solve for the panel's size
    panel_width = (width - m["left"] - m["right"] - (ncols - 1) * m["between_x"]) / ncols
    panel_height = (height - m["bottom"] - top - (nrows - 1) * m["between_y"]) / nrows
    fig.subplots_adjust(left=m["left"] / width, right=1 - m["right"] / width, bottom=m["bottom"] / height,
                        top=1 - top / height, wspace=m["between_x"] / max(panel_width, 0.1),
                        hspace=m["between_y"] / max(panel_height, 0.1))


def stacked_shares(path, rows: list[dict], names, title: str = "", ylabel: str = "share", group: str = "method",
                   bar: str = "h", total: str = "L1") -> None:
    """One panel per value of column ``group``, one stacked bar per row (labelled by ``bar``) of the
    columns ``share_0 ... share_k`` (one per entry of ``names``; each bar sums to 1), ``total`` above it."""
    groups = list(dict.fromkeys(r[group] for r in rows))
    # the legend takes a tenth of the width (tight_layout's rect below)
    nrows, ncols = grid_shape(len(groups), (3.6, 4.0 * 1.1))
    fig, axes = plt.subplots(nrows, ncols, figsize=(3.6 * ncols / 0.89, 4.0 * nrows), sharey=True, squeeze=False)
    colors = plt.cm.tab10(np.arange(len(names)))
    for ax in axes.ravel()[len(groups):]:
        ax.set_visible(False)
    for ax, g in zip(axes.ravel(), groups, strict=False):
        bars = [r for r in rows if r[group] == g]
        labels, bottom = [f"{_value(r[bar]):g}" for r in bars], np.zeros(len(bars))
        for k, name in enumerate(names):
            values = np.array([_value(r[f"share_{k}"]) for r in bars])
            ax.bar(labels, values, bottom=bottom, color=colors[k], label=f"{k} {name}")
            bottom += values
        for j, r in enumerate(bars):
            ax.annotate(f"{_value(r[total]):.2g}", (j, 1.01), ha="center", fontsize=6)
        ax.set_ylim(0, 1.08)
        ax.set_title(g, fontsize=9)
        ax.tick_params(axis="x", labelrotation=45, labelsize=7)
    axes[0][0].set_ylabel(ylabel)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles[::-1], labels[::-1], fontsize=7, loc="center right")
    fig.suptitle(title, fontsize=9)
    fig.tight_layout(rect=(0, 0, 0.89, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    record_caption(path, title)


def save(fig, path, title: str = "", caption: str = "", layout: bool = True) -> None:
    """Title, tight layout (unless ``layout`` is false: the figure is laid out already), PNG at the
    studies' resolution, the figure closed, and its one-line ``caption`` (the title when not given)
    recorded beside it (:func:`record_caption`)."""
    if title:
        fig.suptitle(title, fontsize=9)
    if layout:
        fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    if caption or title:
        record_caption(path, caption or title)


CAPTIONS = "figures.json"


def record_caption(path, caption: str) -> None:
    """Record ``caption`` for the figure ``path`` in ``figures.json`` beside it, which the report reads."""
    path = Path(path)
    index = path.parent / CAPTIONS
    captions = json.loads(index.read_text()) if index.exists() else {}
    captions[path.name] = caption
    index.write_text(json.dumps(dict(sorted(captions.items())), indent=1) + "\n")


def profile_grid(path, exact: dict, rows: dict, title: str = "") -> None:
    """One column per field of ``exact = {field: (x, values)}`` (drawn as a black line in every row;
    ``{row label: {field: (x, values)}}`` for an exact solution per row) and one row per entry of
    ``rows = {row label: [(label, x, {field: values}, fmt, options)]}``; a series draws only the
    fields it has."""
    per_row = isinstance(next(iter(exact.values())), dict)
    fields = next(iter(exact.values())) if per_row else exact
    height = max(3.2, 4 * len(fields) / (MAX_ASPECT * len(rows)))  # at most MAX_ASPECT wide
    fig, axes = plt.subplots(len(rows), len(fields), figsize=(4 * len(fields), height * len(rows)), sharex=True,
                             squeeze=False)
    for axes_row, (row_label, series) in zip(axes, rows.items(), strict=False):
        for ax, (name, (xe, ye)) in zip(axes_row, (exact[row_label] if per_row else exact).items(), strict=False):
            ax.plot(xe, ye, "k-", lw=1.0, label="exact")
            ax.set_title(name, fontsize=9)
            for label, x, values, fmt, options in series:
                if field in values:
                    ax.plot(x, values[field], fmt, label=label, **options)
        axes_row[0].set_ylabel(row_label)
        axes_row[0].legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("x")
    save(fig, path, title)


# ----------------------------------------------------------------------------- figures as data

@dataclass(frozen=True)
class Curve:
    """Column ``y`` against the plot's ``x`` over the rows matching ``where`` (a tuple value: any of
    them), in ``panel``; with ``group`` (columns) one line per combination of their values, ``label``
    formatted with them (``"h = {h}"``). The source's points are a curve of the source's column,
    drawn black and open (``fmt="k*"``)."""

    label: str
    y: str
    fmt: str = "o-"
    where: dict = field(default_factory=dict)
    panel: str = ""
    group: tuple[str, ...] = ()
    options: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Plot:
    """A figure ``file`` with its one-line ``caption`` (also its title), drawn from ``table``; with
    ``split`` (columns) one panel per combination of their values."""

    file: str
    caption: str
    table: str
    x: str
    curves: tuple[Curve, ...]
    xlabel: str = "h"
    ylabel: str = "error"
    slopes: tuple = ()
    size: tuple = (5.2, 4.0)
    split: tuple[str, ...] = ()
    ncols: int | None = None


def _value(v) -> float:
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def _matches(row: dict, where: dict) -> bool:
    """Every column of ``where`` equals its value, or one of its values when that is a tuple."""
    def same(value, wanted):
        return str(value) == str(wanted) or _value(value) == _value(wanted)

    return all(any(same(row.get(k), w) for w in (v if isinstance(v, tuple) else (v,))) for k, v in where.items())


def draw(folder, plot: Plot, rows: list[dict]) -> None:
    """Draw ``plot`` from ``rows`` (as written or as read back: numbers or strings) into ``folder``."""
    content: dict = {}
    for c in plot.curves:
        sel = [r for r in rows if _matches(r, c.where)]
        for key in dict.fromkeys(tuple(r.get(k) for k in plot.split + c.group) for r in sel):
            values = dict(zip(plot.split + c.group, key, strict=False))
            pts = sorted((_value(r[plot.x]), _value(r.get(c.y))) for r in sel if _matches(r, values))
            pts = [(x, y) for x, y in pts if math.isfinite(x) and math.isfinite(y) and y > 0]
            if pts:
                labels = [c.panel] * bool(c.panel) + [f"{k} = {values[k]}" for k in plot.split]
                panel = ", ".join(labels) or plot.caption
                content.setdefault(panel, {})[c.label.format(**values)] = (
                    [x for x, _ in pts], [y for _, y in pts], c.fmt,
                    {"mfc": "none", **c.options} if c.fmt[0] == "k" else c.options)
    panels(Path(folder) / plot.file, content, plot.xlabel, plot.ylabel, plot.caption if len(content) > 1 else "",
           slopes=plot.slopes, size=plot.size, legends=len(content) > 1 and not plot.split, ncols=plot.ncols)
    record_caption(Path(folder) / plot.file, plot.caption)
