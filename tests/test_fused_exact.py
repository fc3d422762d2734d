"""The exact stages compiled (``FusedStep`` with exact projection, mass or interpolation) against
the numpy step with the same stages (mpm_fem.core.step).

The error budget (E1) runs every subset of the stages in MPM or exact form; the fused step runs
the particle passes of each (pass 1, and pass 2 or, with the exact interpolation, ``_move_exact``
and ``_update_exact``) and the numpy step's grid stage (``ExactGridStage``). On a grid not uniform
to round-off the fused step keeps the node arithmetic, so the two runs agree bit for bit; on a
uniform grid the uniform-grid arithmetic agrees to ``TOLERANCE`` (tests/test_fused.py).
"""

import numpy as np
import pytest
from test_fused import TOLERANCE, _assert_same, _drifting_grid, _worst

from mpm_fem.core.grid import grid_from_nodes, uniform_grid
from mpm_fem.core.models.burgers import ViscousBurgers
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.particles import make_particles, seed_positions
from mpm_fem.core.step import Stages, Walls
from mpm_fem.fused.step import FusedStep, supported
from mpm_fem.problems.sod import RiemannFields
from mpm_fem.run import solve
from mpm_fem.run.solve import Problem, run

#: the seven subsets with an exact stage: which of projection, mass, interpolation are exact
SUBSETS = [dict(projection=p, mass=m, interpolation=i)
           for p in ("mpm", "exact") for m in ("lumped", "exact") for i in ("mpm", "exact")
           if "exact" in (p, m, i)]
IDS = ["+".join(k for k, v in s.items() if v == "exact") for s in SUBSETS]
LEFT, RIGHT, X0, GAMMA = (1.0, 0.0, 1.0), (0.125, 0.0, 0.1), 0.5, 1.4


def _sod(grid, steps=200, ppc=4):
    """Sod's tube on ``grid`` (walls), ``steps`` fixed steps, with the exact fields averaged over a
    cell (the Sod problem's half-width h/2)."""
    x, V = seed_positions(grid, ppc, "regular", seed=0)
    left = x < X0
    rho, p = np.where(left, LEFT[0], RIGHT[0]), np.where(left, LEFT[2], RIGHT[2])
    particles = make_particles(x, V, rho, 0.0, p / ((GAMMA - 1.0) * rho), p)
    h = float(np.max(np.diff(grid.nodes)))
    fields = RiemannFields(LEFT, RIGHT, X0, GAMMA, h / 2)
    dt = 0.2 * h / 1.2 / steps * 10  # about a tenth of the CFL step: T = steps dt
    problem = Problem(model=IdealGas(GAMMA, 0.5, 2.0), boundary=Walls(), T=steps * dt, cfl=1.0, dt=dt, exact=fields)
    return problem, particles


def _both(grid, basis, subset, refine=1, steps=200):
    problem, particles = _sod(grid, steps)
    stages = Stages(basis=basis, refine=refine, **subset)
    reference = run(problem, grid, particles, stages, progress=False, kernel="numpy")
    fused = run(problem, grid, particles, stages, progress=False, kernel="fused")
    assert reference.steps >= steps
    assert np.ptp(fused.particles.velocity) > 0.1  # the tube has started to move
    return reference, fused


def _stretched():
    """P1 and GIMP: cells growing left to right (not uniform at all)."""
    return grid_from_nodes(np.linspace(0.0, 1.0, 21) ** 1.1)


# slow: the particle-domain B-spline's (its pass 1 with the stored rows alone 1-1.5 CPU-min of numba on a cold
# cache), uGIMP's and the quadratic's
@pytest.mark.parametrize("basis", [
    "mpm", pytest.param("bspline_gimp", marks=pytest.mark.slow), pytest.param("gimp", marks=pytest.mark.slow),
    pytest.param("bspline", marks=pytest.mark.slow)])
@pytest.mark.parametrize("subset", SUBSETS, ids=IDS)
def test_exact_stages_compiled_equal_the_numpy_step_bit_for_bit(basis, subset):
    """Off a uniform grid the compiled exact stages are the numpy step's operations in its order:
    every particle and nodal field bit for bit after 200 steps of Sod's tube, every subset. P1 and
    GIMP on a stretched grid; the B-splines, which need equal cells, on one whose nodes drift."""
    grid = _drifting_grid() if basis.startswith("bspline") else _stretched()
    assert FusedStep(grid, IdealGas(), Walls()).inv_spacing == 0.0  # the node arithmetic
    reference, fused = _both(grid, basis, subset)
    _assert_same(reference, fused)
    assert _worst(reference, fused) == 0.0


@pytest.mark.parametrize("basis", ["mpm", "gimp", pytest.param("bspline", marks=pytest.mark.slow),
                                   pytest.param("bspline_gimp", marks=pytest.mark.slow)])
def test_exact_stages_compiled_on_a_uniform_grid_within_the_tolerance(basis):
    """On a uniform grid (uniform-grid arithmetic): within ``TOLERANCE`` of the numpy step over
    1,000 steps with every stage exact but the time step, and with the exact interpolation alone,
    the time step halved."""
    grid = uniform_grid(0.0, 1.0, 0.05)
    for subset, refine in ((SUBSETS[-1], 1), (dict(projection="mpm", mass="lumped", interpolation="exact"), 2)):
        reference, fused = _both(grid, basis, subset, refine, steps=1000)
        _assert_same(reference, fused, TOLERANCE)


def test_the_fused_run_takes_no_numpy_step(monkeypatch):
    """A run with exact stages and ``kernel="fused"`` steps compiled: the numpy step is never called."""
    def refuse(*args, **kwargs):
        raise AssertionError("the numpy step was called")

    grid = uniform_grid(0.0, 1.0, 0.05)
    problem, particles = _sod(grid, 20)
    monkeypatch.setattr(solve, "explicit_step", refuse)
    for subset in SUBSETS:
        run(problem, grid, particles, Stages(**subset), progress=False, kernel="fused")
    with pytest.raises(AssertionError, match="numpy step"):
        run(problem, grid, particles, Stages(**SUBSETS[0]), progress=False, kernel="numpy")


def test_which_exact_stages_run_compiled():
    """The gas with USL, the lumped (or exact) mass and the calculated acceleration: compiled; USF,
    the consistent mass and Burgers with exact stages: the numpy step, with the reason."""
    gas = IdealGas()
    for subset in SUBSETS:
        assert supported(gas, Stages(**subset)) is None
        assert "numpy step" in supported(gas, Stages(scheme="usf", **subset))
        assert "numpy step" in supported(ViscousBurgers(0.01), Stages(**subset))
    assert "numpy step" in supported(gas, Stages(projection="exact", mass="consistent"))
    with pytest.raises(ValueError, match="exact fields"):
        FusedStep(uniform_grid(0.0, 1.0, 0.1), gas, Walls(), Stages(interpolation="exact"))


@pytest.mark.slow
def test_exact_stages_on_two_threads_agree_to_round_off_and_repeat_exactly():
    """``threads=2``: each chunk scatters into its own buffer (pass 1) and the exact pass 2 splits
    the particles; equal to one thread to round-off, and the same on every run (deterministic)."""
    grid = uniform_grid(0.0, 1.0, 0.05)
    problem, particles = _sod(grid, 200)
    for basis in ("mpm", "bspline_gimp"):
        stages = Stages(basis=basis, **SUBSETS[0])  # the exact interpolation: _move_exact, _update_exact
        one = run(problem, grid, particles, stages, progress=False)
        two = [run(problem, grid, particles, stages, progress=False, threads=2) for _ in range(2)]
        _assert_same(two[0], two[1])
        _assert_same(one, two[0], TOLERANCE)
