"""The particles: material points carrying mass, volume, velocity and the gas state.

Notation (slides): position ``x_p``, volume (1D: length) ``V_p``, mass ``m_p = rho_p V_p``,
velocity ``v_p``, density ``rho_p``, specific internal energy ``eps_p``, pressure ``p_p``, and
``N_p^i`` particles in cell ``I_i``. Seeding puts ``N_p`` particles in every cell, each with the
volume ``h_i / N_p`` (the slides' ``m_ip = h rho_p / N_p^i``).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from mpm_fem.core.grid import Grid

LAYOUTS = ("regular", "jittered", "random")


class PositivityError(ArithmeticError):
    """A particle lost positivity of density or internal energy."""

    def __init__(self, quantity: str, particle: int, x: float, value: float, step: int | None = None,
                 t: float | None = None):
        self.quantity, self.particle, self.x, self.value = quantity, particle, x, value
        self.step, self.t = step, t
        super().__init__(self._message())

    def _message(self) -> str:
        where = "" if self.step is None else f"at step {self.step} (t={self.t:.6g}) "
        return (
            f"positivity lost {where}in particle {self.particle} at x={self.x:.6g}: "
            f"{self.quantity} = {self.value:.6g}; reduce the CFL number"
        )

    def at(self, step: int, t: float) -> "PositivityError":
        return PositivityError(self.quantity, self.particle, self.x, self.value, step, t)


def check_positive(quantity: str, value: np.ndarray, x: np.ndarray) -> None:
    """Raise :class:`PositivityError` for the first particle whose ``value`` is not > 0 (or NaN)."""
    bad = ~(value > 0)
    if bad.any():
        p = int(np.flatnonzero(bad)[0])
        raise PositivityError(quantity, p, float(x[p]), float(value[p]))


@dataclass(frozen=True, eq=False)
class Particles:
    """State of n_p particles; every field is an (n_p,) float array."""

    x: np.ndarray
    volume: np.ndarray
    mass: np.ndarray
    velocity: np.ndarray
    density: np.ndarray
    energy: np.ndarray
    pressure: np.ndarray
    #: APIC's affine velocity coefficient ``C_p`` (:mod:`mpm_fem.core.transfers.apic`); ``None``: none carried
    affine: np.ndarray | None = None

    def __post_init__(self):
        n = self.x.shape
        for f in fields(self):
            a = getattr(self, f.name)
            if a is None and f.name == "affine":
                continue
            if not isinstance(a, np.ndarray) or a.shape != n:
                raise ValueError(f"particle field {f.name!r} must be an array of shape {n}")

    @property
    def n(self) -> int:
        return self.x.size

    def replace(self, **changes) -> "Particles":
        return replace(self, **changes)

    def take(self, index) -> "Particles":
        """The particles selected by ``index`` (a boolean mask or integer indices)."""
        return Particles(**{f.name: getattr(self, f.name)[index] for f in fields(self)
                            if getattr(self, f.name) is not None})

    def join(self, other: "Particles") -> "Particles":
        """These particles followed by ``other``. Where only one set carries the affine coefficient
        (APIC's ``C_p``; e.g. particles a reservoir adds to an APIC run), the other joins with ``C_p =
        0``, the coefficient APIC starts every particle with."""
        if (self.affine is None) != (other.affine is None):
            self, other = (p if p.affine is not None else p.replace(affine=np.zeros(p.n)) for p in (self, other))
        return Particles(
            **{f.name: np.concatenate((getattr(self, f.name), getattr(other, f.name))) for f in fields(self)
               if getattr(self, f.name) is not None}
        )


def make_particles(x, volume, density, velocity=0.0, energy=0.0, pressure=0.0) -> Particles:
    """Particles at ``x`` with ``m_p = rho_p V_p``; scalars broadcast to every particle."""
    x = np.asarray(x, dtype=float)
    full = lambda a: np.broadcast_to(np.asarray(a, dtype=float), x.shape).copy()  # noqa: E731
    volume, density = full(volume), full(density)
    return Particles(
        x=x.copy(),
        volume=volume,
        mass=density * volume,
        velocity=full(velocity),
        density=density,
        energy=full(energy),
        pressure=full(pressure),
    )


def seed_positions(
    grid: Grid, ppc: int, layout: str = "regular", seed: int | None = 0, jitter: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """Positions and volumes of ``ppc`` particles in every cell, sorted by position.

    ``regular``: midpoints of ``ppc`` equal sub-cells, ``x_{i-1} + (k - 1/2) h_i / N_p``.
    ``jittered``: each regular point moved uniformly within ``+- jitter/2`` of its sub-cell.
    ``random``: ``ppc`` uniform points per cell. Every particle gets the volume ``h_i / N_p``.
    ``seed`` feeds ``numpy.random.default_rng``: the same seed gives the same layout.
    """
    if isinstance(ppc, bool) or not isinstance(ppc, (int, np.integer)) or ppc < 1:
        raise ValueError(f"particles per cell must be an integer >= 1, got {ppc!r}")
    if layout not in LAYOUTS:
        raise ValueError(f"unknown particle layout {layout!r}; choose one of {', '.join(LAYOUTS)}")
    if not 0 <= jitter <= 1:
        raise ValueError(f"jitter must lie in [0, 1], got {jitter}")
    h = grid.h
    left = grid.nodes[:-1]
    if layout == "regular":
        local = (np.arange(ppc) + 0.5) / ppc
        xi = np.broadcast_to(local, (grid.n_cells, ppc))
    elif layout == "jittered":
        rng = np.random.default_rng(seed)
        local = (np.arange(ppc) + 0.5) / ppc
        xi = local + jitter * (rng.random((grid.n_cells, ppc)) - 0.5) / ppc
    else:
        rng = np.random.default_rng(seed)
        xi = np.sort(rng.random((grid.n_cells, ppc)), axis=1)
    x = (left[:, None] + xi * h[:, None]).ravel()
    volume = np.repeat(h / ppc, ppc)
    return x, volume
