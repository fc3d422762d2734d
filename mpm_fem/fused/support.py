"""What the fused step takes (:func:`supported`) and the kernel a run asks for (:func:`check_kernel`).

The fused step (:mod:`mpm_fem.fused.step`) compiles the ideal gas and viscous Burgers, every basis of
the registry and every transfer whose kernels it has: the PIC/FLIP blend and XPIC are its passes' own,
an affine transfer brings its :class:`~mpm_fem.core.transfers.contract.AffineKernels`. It takes the
lumped and the consistent mass (and the exact mass stage): FMPM(k) runs the numpy step. The exact stages
run compiled for the gas, USL, the lumped mass and the calculated acceleration. Anything else runs
the numpy step, and :func:`supported` says why.
"""

from __future__ import annotations

import numpy as np

from mpm_fem.core.models.burgers import ViscousBurgers
from mpm_fem.core.models.euler import IdealGas
from mpm_fem.core.step import Stages
from mpm_fem.core.transfers import get as get_transfer

KERNELS = ("fused", "numpy")
#: the grid masses the fused step solves (``Stages.mass``); the others run the numpy step
COMPILED_MASSES = ("lumped", "consistent", "exact")


def supported(model, stages: Stages) -> str | None:
    """``None`` if the fused step implements this model and these stages, else the reason."""
    if not isinstance(model, (IdealGas, ViscousBurgers)):
        return f"the fused step has no kernel for the model {type(model).__name__}"
    if stages.mass not in COMPILED_MASSES:
        return f"the fused step has no kernels for the grid mass {stages.mass!r}; it runs the numpy step"
    transfer = get_transfer(stages.transfer_name)
    if not transfer.compiled or (transfer.affine and transfer.kernels is None):
        return f"the fused step has no kernels for the transfer {stages.transfer_name!r}; it runs the numpy step"
    if transfer.affine and stages.uses_exact_fields:
        return "an affine transfer with the exact stages runs the numpy step"
    if stages.uses_exact_fields and not (isinstance(model, IdealGas) and stages.scheme == "usl"
                                         and stages.mass in ("lumped", "exact")
                                         and stages.acceleration == "calculated"):
        return ("the exact projection, mass and interpolation stages run compiled for the gas, USL, the lumped "
                "mass and the calculated acceleration; the others run the numpy step")
    return None


def check_kernel(kernel: str, threads: int) -> None:
    """Raise ``ValueError`` for an unknown kernel or a thread count that is not an integer >= 1."""
    if kernel not in KERNELS:
        raise ValueError(f"unknown kernel {kernel!r}; choose one of {', '.join(KERNELS)}")
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise ValueError(f"the number of threads must be an integer >= 1, got {threads!r}")
