"""mpm-fem: the error of the Material Point Method, stage by stage, beside fixed-mesh FEM.

Reproduces and extends L.-T. Tran and M. Berzins, "Error Analysis for Material Point Method and a
case study from Gas Dynamics" (slides; the claims and the source's tables: ``docs/claims.md``).

The notebook entry points, :func:`sod` and :func:`burgers` (:mod:`mpm_fem.app.api`), run one case
with the command line's defaults: ``mpm_fem.sod(h=0.005, ppc=8).errors``. They are imported on first
use, so that ``import mpm_fem`` stays cheap; so are the 2D entry points, ``mpm_fem.plane.axis(h=1/8)``
and ``mpm_fem.plane.vortex(...)`` (:mod:`mpm_fem.app.plane_api`: the 2D package :mod:`mpm_fem.plane`
behind the command line's checks; its other names are the package's). Every bad input they are
given raises :class:`UsageError` (:class:`mpm_fem.app.guard.UsageError`, a ``ValueError``) in one line.
"""

import sys
import types

__version__ = "0.1.0"
__all__ = ["sod", "burgers", "Run", "UsageError"]


def __getattr__(name: str):
    if name == "plane":  # the checked 2D entry points (mpm_fem.plane.axis, .vortex), imported on first use
        from mpm_fem.app import plane_api

        return plane_api
    if name == "UsageError":
        from mpm_fem.app.guard import UsageError

        return UsageError
    if name in __all__:
        from mpm_fem.app import api

        return getattr(api, name)
    raise AttributeError(f"module 'mpm_fem' has no attribute {name!r}")


class _Package(types.ModuleType):
    """This package's module: ``mpm_fem.plane`` is the checked entry points (:func:`__getattr__`) even
    after the 2D package is imported, which binds the package under that name (the binding is ignored:
    ``import mpm_fem.plane.grid`` and ``from mpm_fem.plane import step`` still reach the package)."""

    @property
    def plane(self):
        return __getattr__("plane")

    @plane.setter
    def plane(self, package):
        pass


sys.modules[__name__].__class__ = _Package
