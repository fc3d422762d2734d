"""A pytest plugin: a researcher's tests assert what this study measures about their method.

Installed with the package (entry point ``pytest11``). It adds ``--mpm-basis SPEC`` (a registered
name, an installed entry point's or ``package.module:Name``) and two fixtures:

    mpm_method      :class:`~mpm_fem.app.method.Method` of ``--mpm-basis`` (a test that asks for it
                    fails with a one-line reason if the option is missing or the basis breaks its
                    contract)
    mpm_method_for  a factory, ``mpm_method_for("mypkg.bases:Quartic")``, for tests that name theirs

    def test_my_basis_projects_at_second_order(mpm_method):
        assert mpm_method.projection(layout="regular")["E_m"].lo > 1.9

The package is imported inside the fixtures only: a test session whose tests use neither pays nothing at
collection (no numba import, no compile).
"""

from __future__ import annotations

import pytest


def pytest_addoption(parser):
    group = parser.getgroup("mpm-fem", "the mpm-fem study's measurements of a method")
    group.addoption("--mpm-basis", default=None, metavar="SPEC",
                    help="the basis the mpm_method fixture measures: a registered name or package.module:Name")


@pytest.fixture
def mpm_method_for():
    """``make(spec) -> Method``; a basis that breaks its contract fails the test in one line."""

    def make(spec: str):
        from mpm_fem.app.method import Method
        from mpm_fem.bases.plugins import ContractError

        try:
            return Method(spec)
        except (ContractError, ValueError) as err:
            pytest.fail(str(err), pytrace=False)

    return make


@pytest.fixture
def mpm_method(request, mpm_method_for):
    """The :class:`~mpm_fem.app.method.Method` of ``--mpm-basis``."""
    spec = request.config.getoption("--mpm-basis")
    if spec is None:
        pytest.fail("the mpm_method fixture measures the basis given with --mpm-basis package.module:Name",
                    pytrace=False)
    return mpm_method_for(spec)
