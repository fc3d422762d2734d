"""Error by region of the exact solution (C12) and new extrema created by cell crossings (C14).

Regions (slides, "Final Error Combination"). At time ``t`` the exact Sod solution has, from left
to right, the rarefaction head ``x_H``, its tail ``x_T``, the contact ``x_C`` and the shock
``x_S``. With one half-width ``w`` (the same for every wave and every mesh) the domain is cut into

    0  undisturbed         [a, x_H - w)  and  [x_S + w, b]
    1  rarefaction head    [x_H - w, x_H + w)
    2  smooth              [x_H + w, x_T - w)  (the fan)  and  [x_T + w, x_C - w)  (the plateau)
    3  rarefaction tail    [x_T - w, x_T + w)
    4  contact             [x_C - w, x_C + w)
    5  behind the shock    [x_C + w, x_S - w)  (carries the error the shock leaves behind)
    6  shock front         [x_S - w, x_S + w)

a partition of the domain, so the regional L1 errors ``sum_{k in region} w_k |e_k|`` (weights
``V_p`` over particles, ``int S_i dx`` over nodes) add up to the total L1 error.

New extrema (slides, "Particle Methods applied to Euler Equations": "differing particle velocity
gradients in different cells may lead to new extrema when particles cross over cells"). With the
particles in position order, particle ``p`` is a strict local extremum of a field ``q`` if

    q_p > max(q_{p-1}, q_{p+1}) + tol   or   q_p < min(q_{p-1}, q_{p+1}) - tol,
    tol = rtol * max(|q_{p-1}|, |q_p|, |q_{p+1}|)

(the first and last particle are never extrema). A *new* extremum in a step is a particle that
is an extremum after the step and was not before it. :class:`ExtremaCounter` counts them each
step, separately for the particles that crossed a cell boundary in that step (cell of ``x_p^n``
differs from the cell of ``x_p^{n+1}``) and for those that did not; among the latter, separately
again for the *moving* ones, ``|v_p^{n+1}| > v_min`` (``moving_speed``): a particle at rest ahead of
the waves never crosses and never becomes an extremum, so the comparison that isolates the crossing
is between crossing particles and moving particles that do not cross.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mpm_fem.core.grid import Grid
from mpm_fem.core.particles import Particles
from mpm_fem.fused.codes import FIELDS
from mpm_fem.fused.extrema import Tally, merge, remember, tally_step

REGION_NAMES = (
    "undisturbed",
    "rarefaction head",
    "smooth",
    "rarefaction tail",
    "contact",
    "behind shock",
    "shock front",
)


@dataclass(frozen=True)
class Regions:
    """Breakpoints ``edges`` (increasing, n+1 for n pieces) and the region number of each piece."""

    edges: np.ndarray
    region: np.ndarray

    def index(self, x: np.ndarray) -> np.ndarray:
        """Region number (0..6) of every point of ``x``."""
        piece = np.searchsorted(self.edges, np.asarray(x, dtype=float), side="right") - 1
        return self.region[np.clip(piece, 0, self.region.size - 1)]


def sod_regions(waves: dict, half_width: float, domain: tuple[float, float] = (0.0, 1.0)) -> Regions:
    """The partition of the module docstring from the exact wave positions (``wave_positions``
    of :mod:`baselines.exact.riemann`: keys ``rarefaction_head``, ``rarefaction_tail``,
    ``contact``, ``shock``)."""
    if not half_width > 0:
        raise ValueError(f"the region half-width must be positive, got {half_width}")
    H, T, C, S = (waves[k] for k in ("rarefaction_head", "rarefaction_tail", "contact", "shock"))
    w = half_width
    a, b = domain
    if not (a < H - w and H + w <= T - w and T + w <= C - w and C + w <= S - w and S + w < b):
        raise ValueError(f"half-width {w} makes the regions of waves at {H:.4g}, {T:.4g}, {C:.4g}, {S:.4g} overlap")
    edges = np.array([a, H - w, H + w, T - w, T + w, C - w, C + w, S - w, S + w, b])
    edges[-1] = np.nextafter(b, np.inf)  # the right end belongs to the last piece
    region = np.array([0, 1, 2, 3, 2, 4, 5, 6, 0])
    return Regions(edges=edges, region=region)


def l1_by_region(x: np.ndarray, error: np.ndarray, weights: np.ndarray, regions: Regions) -> np.ndarray:
    """``E_r = sum_{k: x_k in region r} w_k |e_k|`` for r = 0..6; ``sum_r E_r`` is the L1 norm."""
    return np.bincount(regions.index(x), np.asarray(weights) * np.abs(error), len(REGION_NAMES))


def mean_by_region(x: np.ndarray, error: np.ndarray, weights: np.ndarray, regions: Regions) -> np.ndarray:
    """Signed weighted mean ``sum w_k e_k / sum w_k`` of the error in each region (0 where empty):
    a bias (e.g. a density too low on a whole plateau) shows here, noise averages out."""
    index = regions.index(x)
    n = len(REGION_NAMES)
    total = np.bincount(index, np.asarray(weights, dtype=float), n)
    signed = np.bincount(index, np.asarray(weights) * np.asarray(error), n)
    return np.divide(signed, total, out=np.zeros(n), where=total > 0)


def describe(half_width: float, waves: dict, t: float) -> dict:
    """The partition of :func:`sod_regions` in words, for a table's settings."""
    w = half_width
    x = {k: round(waves[k], 5) for k in ("rarefaction_head", "rarefaction_tail", "contact", "shock")}
    return {
        "0 undisturbed": f"[0, x_H - {w}) and [x_S + {w}, 1]", "1 rarefaction head": f"[x_H - {w}, x_H + {w})",
        "2 smooth": f"[x_H + {w}, x_T - {w}) (fan) and [x_T + {w}, x_C - {w}) (plateau)",
        "3 rarefaction tail": f"[x_T - {w}, x_T + {w})", "4 contact": f"[x_C - {w}, x_C + {w})",
        "5 behind shock": f"[x_C + {w}, x_S - {w})", "6 shock front": f"[x_S - {w}, x_S + {w})",
        f"waves at T={t}": ", ".join(f"x_{n} = {v}" for n, v in zip("HTCS", x.values(), strict=True)),
    }


def by_region(x: np.ndarray, error: np.ndarray, weights: np.ndarray, regions: Regions) -> dict[str, list]:
    """``{"L1": l1_by_region, "mean": mean_by_region}`` of one error, as lists (JSON-able)."""
    return {"L1": l1_by_region(x, error, weights, regions).tolist(),
            "mean": mean_by_region(x, error, weights, regions).tolist()}


def first_below(x: np.ndarray, q: np.ndarray, level: float) -> float:
    """First ``x`` (linear between points) where ``q`` drops below ``level``, from the left."""
    k = int(np.argmax(q < level))
    return float(x[k - 1] + (x[k] - x[k - 1]) * (q[k - 1] - level) / (q[k - 1] - q[k]))


def head_shift(x: np.ndarray, rho: np.ndarray, exact, level: float = 0.99, window=(0.2, 0.4)) -> float:
    """Where the computed density first drops below ``level`` minus where the exact one (``exact(x)``,
    sampled finely over ``window``) does: the position error of the rarefaction head (> 0: it lags)."""
    xe = np.linspace(*window, 20001)
    return first_below(x, rho, level) - first_below(xe, exact(xe), level)


def strict_extrema(q: np.ndarray, rtol: float = 1e-9) -> np.ndarray:
    """Boolean mask of strict local extrema of ``q`` (ordered) beyond ``tol`` (module docstring)."""
    q = np.asarray(q, dtype=float)
    out = np.zeros(q.shape, dtype=bool)
    if q.size < 3:
        return out
    left, mid, right = q[:-2], q[1:-1], q[2:]
    tol = rtol * np.maximum(np.maximum(np.abs(left), np.abs(mid)), np.abs(right))
    out[1:-1] = (mid > np.maximum(left, right) + tol) | (mid < np.minimum(left, right) - tol)
    return out


def cells(nodes: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The cell of every point, ``clip(searchsorted(nodes, x, "right") - 1, 0, n_cells - 1)``
    (the readable form of :func:`mpm_fem.fused.extrema.cells`, which a run calls)."""
    return np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, nodes.size - 2)


def new_extrema(nodes: np.ndarray, old: Particles, new: Particles, fields: tuple, rtol: float = 1e-9,
                moving_speed: float = 0.0) -> np.ndarray:
    """One step's counts (module docstring) in the layout of :mod:`mpm_fem.fused.extrema`, readable:
    ``[[1, crossings, moving, particles], [new at crossings, elsewhere, at moving particles, in all] per
    field]``. The reference the compiled count (:func:`~mpm_fem.fused.extrema.tally_step`) is tested against."""
    crossed = cells(nodes, old.x) != cells(nodes, new.x)
    moving = ~crossed & (np.abs(new.velocity) > moving_speed)
    out = np.zeros((1 + len(fields), 4), np.int64)
    out[0] = (1, crossed.sum(), moving.sum(), new.n)
    for f, name in enumerate(fields):
        before, after = (_by_position(getattr(s, name), s.x, rtol) for s in (old, new))
        fresh = after & ~before
        out[1 + f] = ((fresh & crossed).sum(), (fresh & ~crossed).sum(), (fresh & moving).sum(), fresh.sum())
    return out


def _by_position(q: np.ndarray, x: np.ndarray, rtol: float) -> np.ndarray:
    """:func:`strict_extrema` of ``q`` in the position order of ``x`` (a stable sort), per particle."""
    order = np.argsort(x, kind="stable")
    out = np.empty(q.size, bool)
    out[order] = strict_extrema(q[order], rtol)
    return out


@dataclass(eq=False)
class ExtremaCounter:
    """An observer for :func:`mpm_fem.run.solve.run` that counts new extrema of ``fields`` per step
    (module docstring), at crossings, at the other particles and at the other particles that move faster
    than ``moving_speed``, with the compiled count :func:`~mpm_fem.fused.extrema.tally_step`. The compiled
    loop counts too (:meth:`tally`, then :meth:`absorb`): the same integers. After the run, :meth:`summary`
    gives the totals. It keeps no particles (``keeps_particles``): a run may hand it arrays it overwrites
    two steps later; it remembers the last state's cells and extrema, and which particles they are of."""

    keeps_particles = False  # a class attribute, not a field: what solve.run asks of an observer

    grid: Grid
    rtol: float = 1e-9
    fields: tuple = ("density", "energy")
    moving_speed: float = 0.0
    totals: np.ndarray = field(init=False, repr=False)  # (1 + F, 4) int64 (mpm_fem.fused.extrema)
    _memory: tuple | None = field(default=None, repr=False)  # (particles, cells, marks)

    def __post_init__(self):
        unknown = [name for name in self.fields if name not in FIELDS]
        if unknown or not self.fields:
            raise ValueError(f"ExtremaCounter counts fields of {FIELDS}, got {self.fields!r}")
        self.totals = np.zeros((1 + len(self.fields), 4), np.int64)

    @property
    def steps(self) -> int:
        return int(self.totals[0, 0])

    def _rows(self) -> np.ndarray:
        return np.array([FIELDS.index(name) for name in self.fields], np.int64)

    def _remembered(self, particles: Particles) -> tuple[np.ndarray, np.ndarray]:
        """The cells and extremum marks of ``particles``: remembered, or found now."""
        if self._memory is not None and self._memory[0] is particles:
            return self._memory[1], self._memory[2]
        cells_, marks = np.empty(particles.n, np.intp), np.empty((len(self.fields), particles.n), bool)
        remember(self.grid.nodes, _state(particles), self._rows(), self.rtol, cells_, marks)
        return cells_, marks

    def __call__(self, step: int, t: float, old: Particles, new: Particles, state=None) -> None:
        cells_, marks = self._remembered(old)
        counts = np.zeros_like(self.totals)
        tally_step(self.grid.nodes, _state(new), self._rows(), self.rtol, self.moving_speed, counts, cells_, marks)
        merge(self.totals, counts)
        self._memory = (new, cells_, marks)

    def tally(self, particles: Particles) -> Tally:
        """What the compiled loop needs to go on counting from ``particles``."""
        cells_, marks = self._remembered(particles)
        return Tally(self.grid.nodes, self._rows(), float(self.rtol), float(self.moving_speed),
                     np.zeros_like(self.totals), cells_, marks)

    def absorb(self, tally: Tally, particles: Particles) -> None:
        """Add the loop's counts; its memory is of ``particles``, the state it left."""
        merge(self.totals, tally.counts)
        self._memory = (particles, tally.cells, tally.marks)

    def summary(self) -> dict:
        """Totals over the run and rates: new extrema per crossing particle-step, per non-crossing
        particle-step and per moving non-crossing particle-step (``rate_moving``)."""
        steps, crossings, moving, particle_steps = (int(c) for c in self.totals[0])
        staying = particle_steps - crossings
        out = {"steps": steps, "crossings": crossings, "particle_steps": particle_steps,
               "moving_speed": self.moving_speed, "moving_steps": moving}
        for name, row in zip(self.fields, self.totals[1:], strict=True):
            c, s, m, most = (int(k) for k in row)
            out[name] = {
                "new_at_crossing": c,
                "new_elsewhere": s,
                "new_moving": m,
                "new_per_step": (c + s) / max(steps, 1),
                "max_per_step": most,
                "rate_crossing": c / max(crossings, 1),
                "rate_elsewhere": s / max(staying, 1),
                "rate_moving": m / max(moving, 1),
            }
        return out


def _state(particles: Particles) -> np.ndarray:
    """The particles as the compiled loop's rows (``codes.FIELDS``)."""
    return np.vstack([getattr(particles, name) for name in FIELDS])


def plateau_velocity(x: np.ndarray, v: np.ndarray, waves: dict, margin: float) -> dict:
    """Sod's post-shock plateau (contact + margin, shock - margin): the scatter ``std(v_p)`` of the
    particle velocities there (the force quadrature's velocity noise) and the offset of their mean
    from the exact ``u*`` (``waves``: :func:`baselines.exact.riemann.wave_positions`); both NaN
    when no particle lies that far inside the plateau (a mesh too coarse to resolve it)."""
    inside = v[(x > waves["contact"] + margin) & (x < waves["shock"] - margin)]
    if inside.size == 0:
        return {"plateau_noise": float("nan"), "plateau_offset": float("nan")}
    return {"plateau_noise": float(np.std(inside)), "plateau_offset": float(np.mean(inside) - waves["u_star"])}
