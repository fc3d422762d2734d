"""Error norms of a 2D run.

Particles, weighted by their current volumes ``V_p`` and normalised by the total volume (so a
norm is a mean over the body, in the units of the field):

    L2    = sqrt( sum_p V_p |u_p - u(X_p, t)|^2 / sum_p V_p ),
    Linf  = max_p |u_p - u(X_p, t)|,

with ``|.|`` the Euclidean length of the 2-vector, ``u_p = x_p - X_p`` the particle displacement
and ``u`` the exact one at the particle's reference position. Nodes, weighted by the nodal mass
(the nodes without mass are left out):

    L2    = sqrt( sum_i m_i |a_i - a*_i|^2 / sum_i m_i ),

with ``a*_i`` the exact acceleration at the node's position (the material point there at ``t``).
"""

from __future__ import annotations

import numpy as np


def particle_l2(volume: np.ndarray, error: np.ndarray) -> float:
    """``sqrt(sum V_p |e_p|^2 / sum V_p)``; ``volume`` (n_p,), ``error`` (n_p, 2)."""
    return float(np.sqrt(np.sum(volume * np.sum(error**2, axis=1)) / np.sum(volume)))


def particle_linf(error: np.ndarray) -> float:
    """``max_p |e_p|`` (Euclidean length per particle); ``error`` (n_p, 2)."""
    return float(np.sqrt(np.max(np.sum(error**2, axis=1))))


def nodal_l2(mass: np.ndarray, error: np.ndarray) -> float:
    """``sqrt(sum m_i |e_i|^2 / sum m_i)`` over the nodes with mass; ``mass`` (n_nodes,), ``error`` (n_nodes, 2)."""
    w = np.where(mass > 0, mass, 0.0)
    return float(np.sqrt(np.sum(w * np.sum(error**2, axis=1)) / np.sum(w)))
