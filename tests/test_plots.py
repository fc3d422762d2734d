"""The figures' layout (mpm_fem/app/plots.py): a grid of panels gets fixed margins in inches, and a long
figure title is wrapped to the figure's width, its caption kept whole."""

import json

import matplotlib.pyplot as plt
import numpy as np
import pytest

from mpm_fem.app import plots


def test_fixed_margins_are_inches_whatever_the_grid():
    size = (4.2, 3.8)
    for nrows, ncols in ((1, 1), (2, 3)):
        fig, axes = plt.subplots(nrows, ncols, figsize=(size[0] * ncols, size[1] * nrows), squeeze=False)
        plots.fixed_margins(fig, title_lines=2)
        width, height = fig.get_size_inches()
        first, last = axes[0][0].get_position(), axes[-1][-1].get_position()
        assert first.x0 * width == pytest.approx(plots.MARGINS["left"])
        assert (1 - last.x1) * width == pytest.approx(plots.MARGINS["right"])
        assert last.y0 * height == pytest.approx(plots.MARGINS["bottom"])
        top = plots.MARGINS["top"] + 2 * plots.TITLE_MARGIN + 0.1
        assert (1 - first.y1) * height == pytest.approx(top)
        if ncols > 1:
            gap = (axes[0][1].get_position().x0 - first.x1) * width
            assert gap == pytest.approx(plots.MARGINS["between_x"], rel=1e-6)
            vertical = (first.y0 - axes[1][0].get_position().y1) * height
            assert vertical == pytest.approx(plots.MARGINS["between_y"], rel=1e-6)
        plt.close(fig)


def test_a_long_title_is_wrapped_and_its_caption_kept(tmp_path):
    title = "a title far longer than one panel is wide, " * 4
    h = np.array([0.01, 0.005, 0.0025])
    content = {"one": {"MPM": (h, h, "o-")}, "two": {"MPM": (h, 2 * h, "o-")}}
    path = tmp_path / "panels.png"
    plots.panels(path, content, "h", "error", title)
    assert path.stat().st_size > 0
    assert json.loads((tmp_path / plots.CAPTIONS).read_text())["panels.png"] == title
    wrapped = plots.textwrap.fill(title, int(2 * 4.2 * plots.CHARACTERS_PER_INCH))
    assert wrapped.count("\n") >= 1 and max(len(line) for line in wrapped.splitlines()) <= 2 * 4.2 * 13
