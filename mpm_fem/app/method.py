"""The study's measurements for one method, ready for ``assert``: a researcher's basis beside ours.

    >>> from mpm_fem.app.method import Method
    >>> quartic = Method("mpm_quartic:Quartic")          # a registered name, an entry point or module:Name
    >>> quartic.projection()["E_m"]                        # C5-C7's projection orders over seeds
    Order(mean=0.9..., lo=..., hi=..., runs=3)
    >>> quartic.order("sod", hs=(0.02, 0.01), seeds=(1, 2))  # Sod's density L1 order over jittered seeds

:meth:`Method.projection` is :func:`mpm_fem.measure.method.projection_orders` (the nodal mass,
momentum, force and acceleration against the exact integrals of the basis's own grid functions);
:meth:`Method.convergence` and :meth:`Method.order` run :func:`mpm_fem.app.api.convergence` with the
method's basis, in this process (``jobs=1``: a basis registered here is a basis there) and without a
case cache (a researcher's basis changes between runs and is not in the code version). A basis given
as ``module:Name`` is checked against its contract first (:mod:`mpm_fem.bases.plugins`): a broken one
raises :class:`~mpm_fem.bases.plugins.ContractError` naming the failed check.
"""

from __future__ import annotations

from mpm_fem.app.api import convergence
from mpm_fem.app.convergence import Convergence
from mpm_fem.app.inputs import ALIASES
from mpm_fem.bases import plugins
from mpm_fem.measure.method import Order, projection_orders

__all__ = ["Method", "Order"]


class Method:
    """One basis, by name, alias (``p1``) or ``module:Name`` (resolved and checked on construction)."""

    def __init__(self, basis: str):
        self.basis = plugins.resolve(ALIASES["basis"].get(basis, basis))

    def __repr__(self) -> str:
        return f"Method({self.basis!r})"

    def projection(self, cells=(20, 40, 80, 160), ppc: int = 4, layout: str = "jittered",
                   seeds=(1, 2, 3)) -> dict[str, Order]:
        """``{quantity: Order}`` of the projection (:func:`~mpm_fem.measure.method.projection_orders`)."""
        return projection_orders(self.basis, cells, ppc, layout, seeds)

    def convergence(self, problem: str, hs, seeds=(1, 2, 3), **settings) -> Convergence:
        """``problem``'s runs on the meshes ``hs`` and ``seeds`` (0: the regular layout; k >= 1:
        jittered with seed k) with this basis; ``settings`` as :func:`mpm_fem.app.api.convergence`'s."""
        return convergence(problem, hs, seeds, basis=self.basis, jobs=1, progress=False, **settings)

    def order(self, problem: str, hs, seeds=(1, 2, 3), quantity: str = "particles_L1", **settings) -> Order:
        """The order of ``quantity`` (e.g. ``"particles_L1"``, ``"nodes_max"``) fitted over ``hs``:
        its mean and range over ``seeds``. Raises ``RuntimeError`` if a run failed."""
        got = self.convergence(problem, hs, seeds, **settings)
        failed = [r for r in got.runs if not r["ok"]]
        if failed:
            raise RuntimeError(f"{len(failed)} of {len(got.runs)} runs of {self.basis} failed: "
                               f"{failed[0].get('error')}")
        o = got.orders[quantity]
        return Order(o["mean"], o["lo"], o["hi"], o["runs"])
