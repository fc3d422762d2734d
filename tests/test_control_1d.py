"""The 1D control of the 2D study: the axis-aligned solution's x part run by the 1D MPM code.

The bar (:mod:`mpm_fem.run.bar`, the step :mod:`mpm_fem.core.bar` on the periodic grid of
:mod:`mpm_fem.core.periodic`) against the 2D step (:mod:`mpm_fem.plane.step`) with the y amplitude
zero: the 2D particles of one y row move as the 1D particles, row by row. ``AxisAligned`` has one
amplitude for both components, so the 2D solution with the y part off is built here from
``AxisAligned1D`` (:class:`XOnly`): ``u = (u_1D(X, t), 0)``, ``F = diag(F_1D, 1)``, ``b = (b_1D, 0)``;
that ``AxisAligned``'s ``b_x`` is ``AxisAligned1D``'s ``b`` where ``F_y = 1`` is checked first.

Round-off. The two runs sum in different orders (the 2D sums run over the y rows too, and
``sum_b S^y_b = 1`` holds to round-off), so ``x_p``, ``v_p``, ``F_p`` agree to round-off, not bit
for bit. A difference of one unit in the last place of ``F`` changes the stress ``sigma(F)``, which
vanishes at ``F = 1``, by the relative amount ``eps / |F - 1|``, with ``|F - 1| <= pi A``; over
``N`` steps the round-off bound on the relative difference is ``N eps (1 + 1/(pi A))`` (1.4e-11 at
``A = 1e-4``, 3.3e-14 at ``A = 0.05``, 20 steps). Measured (2026-12-01, h = 1/8, 2 (2 x 2) particles
per cell, 20 steps at cfl 0.25): lumped mass, P1 and the quadratic and cubic B-splines, at most 5e-16
for ``x``, ``v``, ``F`` at ``A = 1e-4`` (``x`` and ``F`` bit for bit) and 2.5e-15 at ``A = 0.05``;
the consistent mass 1.4e-12 (``v``, ``A = 1e-4``: the stress's ``eps / |F - 1|``) and 9e-15
(``A = 0.05``). The cubic rows agree only where the 2D grid pads a periodic axis past the cubic's end
functions (the four functions of the open knot vector at each end of a line: five cells at least,
as :mod:`mpm_fem.core.periodic` pads); with three cells the 2D cubic run differs from the bar by 5e-2
in ``v`` (its rows near ``x = 0`` are not the periodic splines).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from baselines.exact.solids import AxisAligned, AxisAligned1D
from mpm_fem.bases import names
from mpm_fem.core.bar import BarParticles
from mpm_fem.core.periodic import periodic_line
from mpm_fem.core.step import Stages
from mpm_fem.plane.grid import plane_grid
from mpm_fem.plane.problems import seed_reference, start
from mpm_fem.plane.step import step_with_grid
from mpm_fem.run.bar import BarSettings, bar, run

H, PPC, STEPS, CFL = 1 / 8, 2, 20, 0.25
EPS = np.finfo(float).eps


@dataclass(frozen=True)
class XOnly:
    """The axis-aligned solution with the y amplitude zero, in the 2D solutions' interface: the bar
    ``AxisAligned1D`` along x, no motion along y."""

    bar: AxisAligned1D

    @property
    def material(self):
        return self.bar.material

    def displacement(self, X, Y, t):
        return np.stack([self.bar.displacement(X, t), np.zeros_like(X)])

    def velocity(self, X, Y, t):
        return np.stack([self.bar.velocity(X, t), np.zeros_like(X)])

    def deformation_gradient(self, X, Y, t):
        F = np.zeros(np.shape(X) + (2, 2))
        F[..., 0, 0] = self.bar.deformation_gradient(X, t)
        F[..., 1, 1] = 1.0
        return F

    def body_force(self, X, Y, t):
        return np.stack([self.bar.body_force(X, t), np.zeros_like(X)])


def bar_steps(A: float, basis: str, mass: str, dt: float) -> list[BarParticles]:
    """The 1D particles after each of ``STEPS`` steps."""
    out = []
    run(BarSettings(h=H, ppc=PPC, amplitude=A, basis=basis, mass=mass, dt=dt, T=STEPS * dt),
        observer=lambda n, t, state, grid_state: out.append(state))
    return out


def row_differences(A: float, basis: str, mass: str) -> tuple[dict, float]:
    """The largest difference over the steps and the y rows of the 2D particles' ``x``, ``v_x`` and
    ``F_xx`` from the 1D particles', each relative to the largest 1D value over the run, and the 2D
    ``v_y`` relative to the largest 1D ``v``; and the round-off bound ``N eps (1 + 1/(pi A))``."""
    solution = XOnly(AxisAligned1D(amplitude=A))
    dt = CFL * H / solution.material.c
    one = bar_steps(A, basis, mass, dt)
    grid = plane_grid((0.0, 0.0), (2.0, 2.0), H, (True, True))
    X, V0, lengths = seed_reference(grid, PPC)
    state = start(solution, X, V0, lengths, dt)
    stages = Stages(basis=basis, mass=mass)
    nx, ny = grid.shape
    worst, scale = dict.fromkeys(("x", "v", "F", "v_y"), 0.0), dict.fromkeys(("x", "v", "F"), 0.0)
    for n in range(STEPS):
        state, _ = step_with_grid(state, grid, basis, solution.material, dt, n * dt, solution.body_force, stages)
        for name, plane, line in (("x", state.x[:, 0], one[n].x), ("v", state.v[:, 0], one[n].v),
                                  ("F", state.F[:, 0, 0], one[n].F)):
            # 2D particles are ordered (cell x, cell y, sub x, sub y); a y row is (cell y, sub y) fixed
            rows = plane.reshape(nx, ny, PPC, PPC).transpose(1, 3, 0, 2).reshape(ny * PPC, nx * PPC)
            worst[name] = max(worst[name], float(np.abs(rows - line[None, :]).max()))
            scale[name] = max(scale[name], float(np.abs(line).max()))
        worst["v_y"] = max(worst["v_y"], float(np.abs(state.v[:, 1]).max()))
    relative = {name: worst[name] / scale["v" if name == "v_y" else name] for name in worst}
    return relative, STEPS * EPS * (1.0 + 1.0 / (np.pi * A))


def test_axis_aligned_x_part_is_the_bar_where_the_y_stretch_is_one():
    """``F_y = 1`` on the line ``Y = 1/2`` (``cos(pi Y) = 0``): there ``AxisAligned``'s ``u_x``,
    ``F_xx`` and ``b_x`` are the bar's."""
    rng = np.random.default_rng(0)
    X, t = rng.uniform(0.0, 2.0, 200), 0.0137
    for A in (1e-4, 0.05):
        plane, line = AxisAligned(amplitude=A), AxisAligned1D(amplitude=A)
        Y = np.full_like(X, 0.5)
        b_plane, b_line = plane.body_force(X, Y, t)[0], line.body_force(X, t)
        gap = np.abs(b_plane - b_line).max() / np.abs(b_line).max()
        assert gap < 1e-13, f"A={A}: AxisAligned b_x differs from AxisAligned1D's b by {gap:.2e} (relative)"
        assert np.allclose(plane.displacement(X, Y, t)[0], line.displacement(X, t), rtol=1e-14, atol=0)
        assert np.allclose(plane.deformation_gradient(X, Y, t)[:, 0, 0], line.deformation_gradient(X, t),
                           rtol=1e-14, atol=0)


@pytest.mark.parametrize("basis", names())
def test_periodic_rows_are_the_same_in_every_cell(basis):
    """On the periodic grid a row shifted by one cell is the same row one node on, for every
    registered basis (the padding keeps the rows off the bases' end functions), and the rows sum to 1."""
    grid = periodic_line(0.0, 2.0, H)
    x = np.linspace(0.0, 2.0, 801)[:-1]
    lengths = np.full(x.size, H / PPC)
    here, there = grid.shape(x, lengths, basis), grid.shape(x + H, lengths, basis)
    gap = np.abs(np.sort(here.S, axis=1) - np.sort(there.S, axis=1)).max()
    assert gap < 1e-13, f"{basis}: the periodic rows differ by {gap:.2e} from one cell to the next"
    moved = np.array_equal(np.sort(there.nodes, axis=1) % grid.n_nodes,
                           np.sort((here.nodes + 1) % grid.n_nodes, axis=1))
    assert moved, f"{basis}: the shifted rows are not one node on"
    unity = np.abs(here.S.sum(axis=1) - 1.0).max()
    assert unity < 1e-13, f"{basis}: the rows sum to 1 within {unity:.2e} only"


@pytest.mark.parametrize("A", [1e-4, 0.05])
@pytest.mark.parametrize("basis, mass", [("mpm", "lumped"), ("bspline", "lumped"), ("cubic", "lumped"),
                                         ("mpm", "consistent")])
def test_plane_run_with_the_y_amplitude_zero_is_the_bar_row_by_row(A, basis, mass):
    """Every y row of the 2D particles equals the 1D particles in ``x``, ``v_x`` and ``F_xx`` at every
    step, to the round-off bound of the module docstring; the 2D y velocity stays at round-off."""
    relative, bound = row_differences(A, basis, mass)
    measured = ", ".join(f"{k} {v:.2e}" for k, v in relative.items())
    assert max(relative.values()) <= bound, \
        f"{basis} {mass}, A={A}: 2D vs 1D relative differences {measured} exceed the round-off bound {bound:.2e}"


def test_bar_refuses_bad_settings():
    with pytest.raises(ValueError, match="mass"):
        BarSettings(mass="exact")
    with pytest.raises(ValueError, match="transfer|scheme"):
        BarSettings(scheme="usf")
    with pytest.raises(ValueError, match="cell size"):
        BarSettings(h=-1.0)
    with pytest.raises(TypeError, match="unknown settings"):
        bar(h=1 / 8, amplitud=1e-4)


@pytest.mark.slow
@pytest.mark.parametrize("basis", ["mpm", "bspline", "cubic"])
def test_bar_displacement_error_is_second_order(basis):
    """At ``A = 1e-4`` (the particles move ``1e-4`` of a cell: no cell crossing) the displacement
    error at one period converges at second order on ``h = 1/8 .. 1/64`` (2 particles per cell,
    cfl 0.25, lumped mass). Measured (2026-12-01): P1 7.1e-6, 1.7e-6, 4.3e-7, 1.1e-7 (orders 2.04,
    2.02, 1.99); quadratic B-spline 1.5e-5 ... 2.2e-7 (2.07, 2.03, 2.01); cubic 1.9e-5 ... 2.8e-7
    (2.07, 2.03, 2.01)."""
    errors = np.array([bar(h=h, basis=basis, amplitude=1e-4).errors["displacement"]["L2"]
                       for h in (1 / 8, 1 / 16, 1 / 32, 1 / 64)])
    orders = np.log2(errors[:-1] / errors[1:])
    assert np.all((orders >= 1.8) & (orders <= 2.2)), \
        f"{basis}: errors {', '.join(f'{e:.3g}' for e in errors)}, orders {', '.join(f'{p:.3f}' for p in orders)}"
