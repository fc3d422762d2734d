"""The bases: each one module behind a contract, read from a registry.

A basis gives each particle its weights ``S_ip`` and derivatives ``G_ip`` at the grid nodes
(:mod:`~mpm_fem.bases.contract` states what it provides). The registered bases, one module each:

    mpm            point mass: the P1 hats at the particle points       :mod:`~mpm_fem.bases.point`
    gimp           the hats averaged over the particle domain            :mod:`~mpm_fem.bases.gimp`
    bspline        the C1 quadratic B-splines at the particle points     :mod:`~mpm_fem.bases.bspline`
    bspline_gimp   the B-splines averaged over the particle domain       :mod:`~mpm_fem.bases.bspline_gimp`
    cubic          the C2 cubic B-splines at the particle points         :mod:`~mpm_fem.bases.cubic`

The rest of the package reads :func:`get` and :func:`names` (:mod:`~mpm_fem.bases.registry`). A new
basis is a module with a :class:`Basis` subclass and its two lines below: its import and its
:func:`register`. Shared pieces: :mod:`~mpm_fem.bases.shape` (:class:`Shape`, the cell of a point)
and :mod:`~mpm_fem.bases.cells` (the compiled cell of a point).
"""

from mpm_fem.bases.bspline import BSpline
from mpm_fem.bases.bspline_gimp import BSplineGimp
from mpm_fem.bases.contract import Basis, Kernels
from mpm_fem.bases.cubic import Cubic
from mpm_fem.bases.gimp import Gimp
from mpm_fem.bases.point import Point
from mpm_fem.bases.registry import IncompleteBasisError, compiled, get, names, register
from mpm_fem.bases.shape import OutsideGridError, Shape, locate

register(Point())
register(Gimp())
register(BSpline())
register(BSplineGimp())
register(Cubic())

__all__ = ["Basis", "IncompleteBasisError", "Kernels", "OutsideGridError", "Shape", "compiled", "get", "locate",
           "names", "register"]
