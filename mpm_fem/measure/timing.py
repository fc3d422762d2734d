"""Time error of the explicit step (C1) and the jump of the third time derivative of ``x_p`` when
a particle crosses a node (C2).

Slides, "Forward Euler time integration": the semi-implicit Euler step

    v_p^{n+1} = v_p^n + dt sum_i S_ip a_i,      x_p^{n+1} = x_p^n + dt sum_i S_ip v_i^{n+1}

has a local error O(dt^2) and a global error O(dt). Both are measured at a fixed mesh and fixed
particles against the same scheme at a much smaller step, which isolates the time error from
every spatial error: the global error ``E(dt) = || q_dt(T) - q_ref(T) ||`` with a fixed ``dt``
(not CFL-adaptive), and the local error of one step from a common state.

The slides' C2: with ``xddot_p = sum_i S_ip a_i`` and P1 hats, in cell ``[x_{i-1}, x_i]``
``xdddot_p = alpha_i adot_{i-1} + (1 - alpha_i) adot_i + v_p (a_{i-1} - a_i)/(x_{i-1} - x_i)``, so
when the particle crosses node ``i``

    [xdddot^+ - xdddot^-]_{x_i} = v_p [(a_i - a_{i+1})/(x_i - x_{i+1}) - (a_{i-1} - a_i)/(x_{i-1} - x_i)].

:func:`crossing_jumps` records ``A_p^n = sum_i S_ip a_i^n = (v_p^{n+1} - v_p^n)/dt`` along one
particle's path, fits a quadratic in ``t`` to the steps on each side of every node crossing, and
takes the difference of the two slopes at the crossing time: the measured jump, beside the formula.
A C1 basis (GIMP, quadratic B-spline) makes ``sum_i S_ip a_i`` C1 in ``x_p``: no jump.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

from mpm_fem.core.grid import uniform_grid
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.particles import Particles, make_particles, seed_positions
from mpm_fem.core.step import Stages, Walls, explicit_step
from mpm_fem.exact_stages import FieldStages
from mpm_fem.run.solve import Problem, Result, run


@dataclass(frozen=True)
class PulseSettings:
    """A smooth acoustic pulse in an ideal gas on [0, 1] between walls (no shock before ``T``):

        rho = 1,  u = 0,  p = 1 + amplitude exp(-((x - 1/2)/width)^2),

    no artificial viscosity (the flow stays smooth), and a fixed time step
    ``dt = cfl h / c_0 / refine`` with ``c_0 = sqrt(gamma (1 + amplitude))`` the largest initial
    sound speed.
    """

    # the mesh, the particles and the time step
    h: float = 0.02
    ppc: int = 4
    T: float = 0.1
    cfl: float = 0.4
    # the pulse
    amplitude: float = 0.2
    width: float = 0.1
    gamma: float = 1.4
    # the stages
    basis: str = "mpm"
    refine: int = 1

    @property
    def dt(self) -> float:
        return self.cfl * self.h / np.sqrt(self.gamma * (1 + self.amplitude)) / self.refine

    def as_dict(self) -> dict:
        return asdict(self)


def pulse_setup(settings: PulseSettings) -> tuple[Problem, object, Particles, Stages]:
    """Problem, grid, initial particles and stages of the smooth pulse."""
    grid = uniform_grid(0.0, 1.0, settings.h)
    x, volume = seed_positions(grid, settings.ppc, "regular")
    p = 1.0 + settings.amplitude * np.exp(-(((x - 0.5) / settings.width) ** 2))
    gas = IdealGas(settings.gamma, 0.0, 0.0)
    particles = make_particles(x, volume, 1.0, 0.0, p / (settings.gamma - 1.0), p)
    # the step is fixed: dt is exact, refine only names the run
    problem = Problem(model=gas, boundary=Walls(), T=settings.T, cfl=1.0, dt=settings.dt)
    return problem, grid, particles, Stages(basis=settings.basis)


def simulate_pulse(settings: PulseSettings) -> Result:
    problem, grid, particles, stages = pulse_setup(settings)
    return run(problem, grid, particles, stages, progress=False)


def field_on(points: np.ndarray, x: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The piecewise-linear field through the particle values ``(x_p, q_p)``, at ``points``."""
    order = np.argsort(x, kind="stable")
    return np.interp(points, x[order], q[order])


def field_difference(a: Particles, b: Particles, interval: tuple[float, float], quantity: str = "velocity",
                     n_points: int = 4001) -> float:
    """``(1/|I|) int_I |q_a - q_b| dx`` of the piecewise-linear particle fields on ``interval``.

    Compares runs whose particle sets differ (inflow reservoirs) without matching particles.
    """
    points = np.linspace(*interval, n_points)
    d = np.abs(field_on(points, a.x, getattr(a, quantity)) - field_on(points, b.x, getattr(b, quantity)))
    return float(np.trapezoid(d, points) / (interval[1] - interval[0]))


def observed_order(steps, errors) -> np.ndarray:
    """Orders between successive time steps: ``log(E_k / E_{k+1}) / log(dt_k / dt_{k+1})``."""
    steps, errors = np.asarray(steps, float), np.asarray(errors, float)
    return np.log(errors[:-1] / errors[1:]) / np.log(steps[:-1] / steps[1:])


def local_errors(problem: Problem, grid, particles: Particles, stages: Stages, t: float, dts, substeps: int = 256,
                 exact=None) -> list[dict]:
    """One step of each ``dt`` in ``dts`` from ``(particles, t)`` against ``substeps`` steps of
    ``dt / substeps`` over the same interval: ``max_p |x_p - x_p^ref|`` and ``max_p |v_p - v_p^ref|``."""
    fields = problem.exact if exact is None else exact
    exact_stages = FieldStages(fields) if fields is not None else None

    def advance(p, t0, dt, n):
        for k in range(n):
            p, _ = explicit_step(grid, p, problem.model, problem.boundary, t0 + k * dt, dt, stages,
                                 problem.exact_acceleration, exact_stages)
        return p

    rows = []
    for dt in dts:
        one = advance(particles, t, dt, 1)
        ref = advance(particles, t, dt / substeps, substeps)
        rows.append({"dt": dt, "x": float(np.abs(one.x - ref.x).max()),
                     "velocity": float(np.abs(one.velocity - ref.velocity).max())})
    return rows


def state_at(problem: Problem, grid, particles: Particles, stages: Stages, t: float) -> Particles:
    """The particles of ``problem`` run to time ``t``."""
    return run(replace(problem, T=t), grid, particles, stages, progress=False).particles


@dataclass(frozen=True)
class Track:
    """One particle's path: per step ``n`` the time ``t^n``, position ``x_p^n``, velocity ``v_p^n``,
    ``A^n = (v_p^{n+1} - v_p^n)/dt`` (``= sum_i S_ip a_i^n``), the velocity that moved it
    ``(x_p^{n+1} - x_p^n)/dt`` and the nodal accelerations ``a_i^n`` (n_steps, n_nodes)."""

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    A: np.ndarray
    moving: np.ndarray
    a_nodes: np.ndarray


class Recorder:
    """An observer for :func:`mpm_fem.run.solve.run` that records particle ``index`` (a :class:`Track`).

    The index must stay valid: no particle before it may be removed (true for a particle that does
    not leave, with inflow particles appended at the end).
    """

    keeps_particles = False  # it copies the particle's numbers and the nodal accelerations at once

    def __init__(self, index: int):
        self.index = index
        self.rows: list[tuple] = []
        self.a_nodes: list[np.ndarray] = []

    def __call__(self, step, t, old, new, state):
        p = self.index
        self.rows.append((t, old.x[p], old.velocity[p], new.velocity[p], new.x[p]))
        self.a_nodes.append(state.acceleration.copy())

    def track(self) -> Track:
        t, x, v, v_new, x_new = (np.array(c) for c in zip(*self.rows, strict=True))
        dt = np.diff(np.append(t, np.nan))
        # the last step's length is unknown from t alone: use the previous one
        dt[-1] = dt[-2] if dt.size > 1 else np.nan
        return Track(t, x, v, (v_new - v) / dt, (x_new - x) / dt, np.array(self.a_nodes))


def crossing_jumps(track: Track, nodes: np.ndarray, window: int = 8, skip: int = 1) -> list[dict]:
    """The jump of ``dA/dt`` (``A = xddot_p``) at every node the particle crosses, measured and
    predicted by the slides' formula (module docstring), for interior nodes with ``window + skip``
    steps on each side of the crossing.

    Measured: quadratic least-squares fits of ``A(t)`` to ``window`` steps on each side (leaving
    out the ``skip`` steps nearest the crossing), differentiated at the crossing time ``t_c``.
    Predicted: ``v_p [(a_{i+1} - a_i)/h_+ - (a_i - a_{i-1})/h_-]`` with ``a`` and ``v_p`` linearly
    interpolated to ``t_c``; the sign is that of ``after - before`` for either direction of motion.
    """
    rows = []
    x, t = track.x, track.t
    cell = np.searchsorted(nodes, x, side="right") - 1
    for n in np.flatnonzero(np.diff(cell) != 0):
        forward = cell[n + 1] > cell[n]
        i = cell[n + 1] if forward else cell[n]
        if abs(int(cell[n + 1]) - int(cell[n])) != 1 or not 0 < i < nodes.size - 1:
            continue
        lo, hi = n - skip - window + 1, n + 1 + skip + window
        if lo < 0 or hi > t.size:
            continue
        s = (nodes[i] - x[n]) / (x[n + 1] - x[n])
        t_c = t[n] + s * (t[n + 1] - t[n])
        before = slice(lo, n - skip + 1)
        after = slice(n + 1 + skip, hi)
        slope = []
        for part in (before, after):
            coef = np.polyfit(t[part] - t_c, track.A[part], 2)
            slope.append(coef[1])
        a = (1 - s) * track.a_nodes[n] + s * track.a_nodes[n + 1]
        v_p = (1 - s) * track.v[n] + s * track.v[n + 1]
        h_minus, h_plus = nodes[i] - nodes[i - 1], nodes[i + 1] - nodes[i]
        formula = v_p * ((a[i] - a[i + 1]) / (nodes[i] - nodes[i + 1]) - (a[i - 1] - a[i]) / (nodes[i - 1] - nodes[i]))
        rows.append({
            "node": int(i), "x_node": float(nodes[i]), "t_cross": float(t_c), "v_p": float(v_p),
            "direction": "right" if forward else "left",
            "measured": float(slope[1] - slope[0]),
            "predicted": float(formula if forward else -formula),
            "slope_before": float(slope[0]),
            "curvature_term": float((a[i + 1] - a[i]) / h_plus - (a[i] - a[i - 1]) / h_minus),
        })
    return rows
