"""Figures: final profiles against the exact solution, and convergence plots with reference slopes."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def profiles(path, x_exact, exact: dict, x_particles, particles: dict, x_nodes=None, nodes: dict | None = None, title: str = ""):
    """One panel per field: exact (line), particles (dots), grid nodes (crosses). Saves a PNG."""
    names = list(exact)
    fig, axes = plt.subplots(1, len(names), figsize=(4.2 * len(names), 3.6), squeeze=False)
    for ax, name in zip(axes[0], names):
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
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def convergence(path, series: dict, xlabel: str = "h", ylabel: str = "error", slopes=(1, 2), title: str = ""):
    """Log-log error against ``h``: ``series = {label: (h, error, style)}``, with slope guides."""
    fig, ax = plt.subplots(figsize=(5.2, 4.0))
    hs = []
    for label, (h, err, *style) in series.items():
        ax.loglog(h, err, style[0] if style else "o-", label=label, ms=4)
        hs.append(np.asarray(h, float))
        anchor = (np.asarray(h, float)[0], np.asarray(err, float)[0])
    if hs:
        h_all = np.unique(np.concatenate(hs))
        h0, e0 = anchor
        for k in slopes:
            ax.loglog(h_all, e0 * (h_all / h0) ** k, ":", color="gray", lw=0.9)
            ax.annotate(f"slope {k}", (h_all[0], e0 * (h_all[0] / h0) ** k), fontsize=7, color="gray")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=7)
    if title:
        ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


# ----------------------------------------------------------------------------- the studies' conventions

def slope_guides(ax, h, e0: float, slopes=(1, 2)) -> None:
    """Dotted grey lines ``e0 (h / h_max)^k`` over the range of ``h``, one per slope ``k``, labelled."""
    h = np.sort(np.asarray(h, float))
    for k in slopes:
        ax.loglog(h, e0 * (h / h[-1]) ** k, ":", color="gray", lw=0.8)
        ax.annotate(f"slope {k:g}", (h[0], e0 * (h[0] / h[-1]) ** k), fontsize=6, color="gray")


def panels(path, content: dict, xlabel: str, ylabel: str, title: str = "", ncols: int | None = None,
           slopes=(), size=(4.2, 3.8), log: bool = True) -> None:
    """One panel per entry of ``content = {panel title: {label: (x, y, fmt, options)}}`` (``options``
    optional: matplotlib keywords), log-log unless ``log`` is false, with slope guides through the
    largest value of each panel and the legend in the first one. The source's points are a series
    like any other, drawn black and open (fmt ``"ks"``/``"ko"``/``"k*"``, ``mfc="none"``)."""
    names = list(content)
    ncols = ncols or len(names)
    nrows = -(-len(names) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(size[0] * ncols, size[1] * nrows), squeeze=False)
    for ax, name in zip(axes.ravel(), names):
        xs, top = [], 0.0
        for label, (x, y, fmt, *options) in content[name].items():
            y = np.asarray(y, float)
            (ax.loglog if log else ax.plot)(x, y, fmt, label=label, **{"ms": 3.5, "lw": 1.1, **(options[0] if options else {})})
            xs += list(x)
            top = max(top, np.nanmax(y, initial=0.0))
        if slopes and top > 0:
            slope_guides(ax, xs, top * 1.3, slopes)
        ax.set_title(name, fontsize=9)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
    for ax in axes.ravel()[len(names):]:
        ax.set_visible(False)
    axes[0][0].legend(fontsize=6, markerscale=1.5)
    save(fig, path, title)


def stacked_shares(path, groups: dict, names, title: str = "", ylabel: str = "share") -> None:
    """One panel per group, ``groups = {group: [(bar label, [share per name], total)]}``: stacked
    bars that each sum to 1, the total printed above each bar."""
    fig, axes = plt.subplots(1, len(groups), figsize=(3.6 * len(groups), 4.0), sharey=True, squeeze=False)
    colors = plt.cm.tab10(np.arange(len(names)))
    for ax, (group, bars) in zip(axes[0], groups.items()):
        bottom = np.zeros(len(bars))
        for k, name in enumerate(names):
            values = np.array([shares[k] for _, shares, _ in bars])
            ax.bar([label for label, _, _ in bars], values, bottom=bottom, color=colors[k], label=f"{k} {name}")
            bottom += values
        for j, (_, _, total) in enumerate(bars):
            ax.annotate(f"{total:.2g}", (j, 1.01), ha="center", fontsize=6)
        ax.set_ylim(0, 1.08)
        ax.set_title(group, fontsize=9)
        ax.tick_params(axis="x", labelrotation=45, labelsize=7)
    axes[0][0].set_ylabel(ylabel)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles[::-1], labels[::-1], fontsize=7, loc="center right")
    fig.suptitle(title, fontsize=9)
    fig.tight_layout(rect=(0, 0, 0.89, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def save(fig, path, title: str = "") -> None:
    """Title, tight layout, PNG at the studies' resolution, and the figure closed."""
    if title:
        fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
