"""mpm-fem: the error of the Material Point Method, stage by stage, beside fixed-mesh FEM.

Reproduces and extends L.-T. Tran and M. Berzins, "Error Analysis for Material Point Method and a
case study from Gas Dynamics" (slides; the claims and the source's tables: ``docs/claims.md``).

The notebook entry points, :func:`sod` and :func:`burgers` (:mod:`mpm_fem.app.api`), run one case
with the command line's defaults: ``mpm_fem.sod(h=0.005, ppc=8).errors``. They are imported on first
use, so that ``import mpm_fem`` stays cheap; so is the 2D package, ``mpm_fem.plane.axis(h=1/16)``.
Every bad input they are given raises :class:`UsageError` (:class:`mpm_fem.app.guard.UsageError`, a
``ValueError``) in one line.
"""

__version__ = "0.1.0"
__all__ = ["sod", "burgers", "Run", "UsageError"]


def __getattr__(name: str):
    if name == "plane":  # the 2D package (mpm_fem.plane.axis, .vortex), imported on first use
        import mpm_fem.plane

        return mpm_fem.plane
    if name == "UsageError":
        from mpm_fem.app.guard import UsageError

        return UsageError
    if name in __all__:
        from mpm_fem.app import api

        return getattr(api, name)
    raise AttributeError(f"module 'mpm_fem' has no attribute {name!r}")
