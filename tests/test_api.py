"""The notebook entry points: ``docs/api.md`` is run as a doctest (its examples are the test)."""

from __future__ import annotations

import doctest
from pathlib import Path

import pytest

import mpm_fem

DOCS = Path(__file__).resolve().parent.parent / "docs" / "api.md"


def test_the_api_page_examples_give_the_numbers_they_show():
    failures, tried = doctest.testfile(str(DOCS), module_relative=False,
                                       optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert tried > 5 and failures == 0


def test_the_entry_points_agree_with_the_solver_and_the_exact_solution():
    run = mpm_fem.sod(h=0.02, ppc=2, T=0.05)
    density = run.particles.density - run.exact["particles"]["density"]
    l1 = float((abs(density) * run.particles.volume).sum())
    assert l1 == pytest.approx(run.errors["density"]["particles"]["L1"], rel=1e-12)
    assert run.nodal["density"].shape == run.nodes.shape == run.exact["nodes"]["density"].shape


def test_a_run_too_large_is_refused_before_it_starts():
    from mpm_fem.app.guard import UsageError

    with pytest.raises(UsageError, match="over the limit|over"):
        mpm_fem.sod(h=1e-7)


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'shock'"):
        mpm_fem.shock  # noqa: B018
