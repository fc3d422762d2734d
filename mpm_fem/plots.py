"""Figures: final profiles against the exact solution, and convergence plots with reference slopes."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def profiles(path, x_exact, exact: dict, x_particles, particles: dict, x_nodes=None, nodes: dict | None = None, title: str = ""):
    """One panel per field: exact (line), particles (dots), grid nodes (crosses). Saves a PNG; the
    layout is constrained, so the title (lines split by ``\\n``) fits above the panels."""
    names = list(exact)
    fig, axes = plt.subplots(1, len(names), figsize=(max(4.2 * len(names), 6.0), 3.8), squeeze=False,
                             layout="constrained")
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
