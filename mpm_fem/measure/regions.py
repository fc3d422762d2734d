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
from numba import njit

from mpm_fem.core.grid import Grid
from mpm_fem.core.particles import Particles

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
    (the readable form; :func:`_cells` is the one a run calls per step)."""
    return np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, nodes.size - 2)


@njit(cache=True)
def _cells(nodes, x):
    """:func:`cells` compiled: for each point the last node ``j`` with ``nodes[j] <= x`` (-1 if
    none; the last node for NaN, where ``searchsorted`` sorts it), clipped to the cells, found by
    walking from the previous point's node. The particles are nearly in position order, so a step
    costs O(particles + nodes), not a binary search per particle: the same integers."""
    m = nodes.size
    out = np.empty(x.size, np.intp)
    j = -1  # the last node <= the previous point
    for p in range(x.size):
        y = x[p]
        if y != y:
            j = m - 1
        else:
            while j + 1 < m and nodes[j + 1] <= y:
                j += 1
            while j >= 0 and not (nodes[j] <= y):
                j -= 1
        out[p] = min(max(j, 0), m - 2)
    return out


def _in_order(q: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """``q`` in position order (``x`` is usually sorted already: no sort then)."""
    if np.all(x[1:] >= x[:-1]):
        return q, None
    order = np.argsort(x, kind="stable")
    return q[order], order


@njit(cache=True)
def _strict_extrema(q, rtol):
    """:func:`strict_extrema` of ordered finite values, compiled (one pass, no temporaries): the same
    comparisons of the same floats, so the same mask (a run's particles are finite: it stops on the
    first that is not)."""
    n = q.size
    out = np.zeros(n, np.bool_)
    for k in range(1, n - 1):
        left, mid, right = q[k - 1], q[k], q[k + 1]
        tol = rtol * max(max(abs(left), abs(mid)), abs(right))
        out[k] = mid > max(left, right) + tol or mid < min(left, right) - tol
    return out


def _extrema_in_particle_order(q: np.ndarray, x: np.ndarray, rtol: float) -> np.ndarray:
    ordered, order = _in_order(q, x)
    mask = _strict_extrema(np.ascontiguousarray(ordered, dtype=float), float(rtol))
    if order is None:
        return mask
    out = np.empty_like(mask)
    out[order] = mask
    return out


@dataclass(eq=False)
class ExtremaCounter:
    """An observer for :func:`mpm_fem.run.solve.run` that counts new extrema of density and energy
    per step (module docstring), at crossings, at the other particles and at the other particles
    that move faster than ``moving_speed``. After the run, :meth:`summary` gives the totals. It keeps
    no particles (``keeps_particles``): a run may hand it arrays it overwrites two steps later."""

    keeps_particles = False  # a class attribute, not a field: what solve.run asks of an observer

    grid: Grid
    rtol: float = 1e-9
    fields: tuple = ("density", "energy")
    moving_speed: float = 0.0
    steps: int = 0
    crossings: int = 0
    particle_steps: int = 0
    moving_staying: int = 0
    new_crossing: dict = field(default_factory=dict)
    new_staying: dict = field(default_factory=dict)
    new_moving: dict = field(default_factory=dict)
    per_step_max: dict = field(default_factory=dict)
    _last: tuple | None = field(default=None, repr=False)

    def __call__(self, step: int, t: float, old: Particles, new: Particles, state=None) -> None:
        # the state after one step is the state before the next: reuse what was computed for it
        if self._last is not None and self._last[0] is old:
            old_cell, before = self._last[1], self._last[2]
        else:
            old_cell = _cells(self.grid.nodes, old.x)
            before = {n: _extrema_in_particle_order(getattr(old, n), old.x, self.rtol) for n in self.fields}
        new_cell = _cells(self.grid.nodes, new.x)
        after = {n: _extrema_in_particle_order(getattr(new, n), new.x, self.rtol) for n in self.fields}
        self._last = (new, new_cell, after)
        crossed = old_cell != new_cell
        moving = ~crossed & (np.abs(new.velocity) > self.moving_speed)
        self.steps += 1
        self.crossings += int(np.count_nonzero(crossed))
        self.moving_staying += int(np.count_nonzero(moving))
        self.particle_steps += new.n
        for name in self.fields:
            fresh = after[name] & ~before[name]
            total = int(np.count_nonzero(fresh))
            at_crossing = int(np.count_nonzero(fresh & crossed)) if total else 0
            self.new_crossing[name] = self.new_crossing.get(name, 0) + at_crossing
            self.new_staying[name] = self.new_staying.get(name, 0) + total - at_crossing
            self.new_moving[name] = self.new_moving.get(name, 0) + (int(np.count_nonzero(fresh & moving))
                                                                    if total else 0)
            self.per_step_max[name] = max(self.per_step_max.get(name, 0), total)

    def summary(self) -> dict:
        """Totals over the run and rates: new extrema per crossing particle-step, per non-crossing
        particle-step and per moving non-crossing particle-step (``rate_moving``)."""
        staying = self.particle_steps - self.crossings
        out = {"steps": self.steps, "crossings": self.crossings, "particle_steps": self.particle_steps,
               "moving_speed": self.moving_speed, "moving_steps": self.moving_staying}
        for name in self.fields:
            c, s, m = self.new_crossing.get(name, 0), self.new_staying.get(name, 0), self.new_moving.get(name, 0)
            out[name] = {
                "new_at_crossing": c,
                "new_elsewhere": s,
                "new_moving": m,
                "new_per_step": (c + s) / max(self.steps, 1),
                "max_per_step": self.per_step_max.get(name, 0),
                "rate_crossing": c / max(self.crossings, 1),
                "rate_elsewhere": s / max(staying, 1),
                "rate_moving": m / max(self.moving_staying, 1),
            }
        return out


def plateau_velocity(x: np.ndarray, v: np.ndarray, waves: dict, margin: float) -> dict:
    """Sod's post-shock plateau (contact + margin, shock - margin): the scatter ``std(v_p)`` of the
    particle velocities there (the force quadrature's velocity noise) and the offset of their mean
    from the exact ``u*`` (``waves``: :func:`baselines.exact.riemann.wave_positions`); both NaN
    when no particle lies that far inside the plateau (a mesh too coarse to resolve it)."""
    inside = v[(x > waves["contact"] + margin) & (x < waves["shock"] - margin)]
    if inside.size == 0:
        return {"plateau_noise": float("nan"), "plateau_offset": float("nan")}
    return {"plateau_noise": float(np.std(inside)), "plateau_offset": float(np.mean(inside) - waves["u_star"])}
