"""The fused step: :func:`mpm_fem.core.step.explicit_step` compiled with numba, in a few passes over
the particles.

    pass 1   S_ip, G_ip at x_p^n;  m_i, P_i (and, for the gas, F_i = sum_p V_p p_p G_ip)
    grid     v_i = P_i / m_i (or M^{-1} P_i), a_i, v_i^{n+1}, boundary conditions (numpy)
    pass 2   v_p += dt sum_i S_ip a_i;  x_p += dt sum_i S_ip v_i^{n+1};  L_p = sum_i G_ip v_i^{n+1};
             the model's state update; max_p (c_p + |v_p|) for the next time step; the
             positivity and finiteness checks

(viscous Burgers, USF and MUSL add one pass each). Contract: every sum is taken in the numpy step's
order (particles in index order, a particle's nodes left to right) with the same operations, so on
one thread the fused step equals :func:`~mpm_fem.core.step.explicit_step` bit for bit, except on a
grid uniform to round-off (nodes within ``1e-9 h`` of ``x_0 + i h``), where every basis takes
uniform-grid arithmetic (``s = (x - x_0)/h``): equal to round-off (1e-12 relative over 1,000 steps).
On ``threads > 1`` the particles are cut into contiguous chunks whose grid sums are added in chunk
order: deterministic, equal to the one-thread step to round-off. The compiled loop
(:meth:`~mpm_fem.fused.step.FusedStep.advance`) equals the per-step path bit for bit.

Supported: every registered basis (:mod:`mpm_fem.bases`: each gives its rows as compiled kernels,
which the variants take as globals), USL, USF, MUSL, lumped and consistent mass, calculated or exact
acceleration, the ideal gas and viscous Burgers, and every remedy (the PIC/FLIP blend, XPIC(m), the
grid volume, the Taylor reconstruction) and the transfers whose kernels it has (the blend, XPIC, APIC's
affine kernels; APIC per step, not in the loop); the exact stages for the gas with USL, the lumped mass and
the calculated acceleration (:func:`~mpm_fem.fused.support.supported` says which run the numpy step).

Modules, in the order of the step: :mod:`~mpm_fem.fused.codes` (compile-time codes, named indices),
:mod:`~mpm_fem.fused.sums` (gathers, scatters, chunk sums), :mod:`~mpm_fem.fused.models` (a
particle's state update and the checks), :mod:`~mpm_fem.fused.project` (pass 1),
:mod:`~mpm_fem.fused.passes` (pass 2 and the passes around it), :mod:`~mpm_fem.fused.remedies` (the
volume reset, the Taylor force), :mod:`~mpm_fem.fused.loop` (many steps in one call),
:mod:`~mpm_fem.fused.compiler` (the variants and what each replaces), :mod:`~mpm_fem.fused.support`
(what it takes) and :mod:`~mpm_fem.fused.step`
(:class:`~mpm_fem.fused.step.FusedStep`). How the passes were made fast: ``docs/performance.md``.
"""

from mpm_fem.fused.codes import BURGERS, GAS
from mpm_fem.fused.models import all_finite
from mpm_fem.fused.step import KERNELS, FusedStep, check_kernel, supported

__all__ = ["BURGERS", "GAS", "KERNELS", "FusedStep", "all_finite", "check_kernel", "supported"]
