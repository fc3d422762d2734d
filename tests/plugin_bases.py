"""Bases as a researcher's package would write them, for ``test_plugins.py`` (``plugin_bases:Name``).

``Hats`` is the point-mass basis under another name without compiled kernels (the numpy step only);
the others each break one check of :func:`mpm_fem.bases.plugins.verify`.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from mpm_fem.bases import get
from mpm_fem.bases.point import Point


class Hats(Point):
    """The P1 hats at the particle points, numpy rows only."""

    name = "hats"
    title = "P1 hats, numpy only"
    grid_functions = "hats"
    kernels = None


class HatsCompiled(Point):
    """The P1 hats with the point basis's own compiled kernels: passes every check."""

    name = "hats_compiled"
    title = "P1 hats, compiled"
    grid_functions = "hats_compiled"


class _Broken(Hats):
    """A numpy-only P1 whose rows one subclass spoils."""

    def spoil(self, shape):
        return shape

    def shape(self, grid, x, volume=None):
        return self.spoil(super().shape(grid, x, volume))


class Heavy(_Broken):
    """Weights 1 % too large: no partition of unity."""

    name = "heavy"

    def spoil(self, shape):
        return dataclasses.replace(shape, S=1.01 * shape.S)


class NotFinite(_Broken):
    """A NaN weight."""

    name = "not_finite"

    def spoil(self, shape):
        S = shape.S.copy()
        S[3, 0] = np.nan
        return dataclasses.replace(shape, S=S)


class Ragged(_Broken):
    """Derivative rows one column short."""

    name = "ragged"

    def spoil(self, shape):
        return dataclasses.replace(shape, G=shape.G[:, :1])


class WrongKernel(Point):
    """P1 numpy rows with the quadratic B-spline's compiled row: they disagree."""

    name = "wrong_kernel"
    grid_functions = "wrong_kernel"
    kernels = get("bspline").kernels


class Nameless:
    """Not a basis at all."""


NOT_A_CLASS = 3
