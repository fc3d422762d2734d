"""Cost of one Sod step with APIC against FLIP, fused and numpy, measured in the same run.

Per particle count (point mass, USL, lumped mass, 4 per cell): the best of ``--repeat`` calls of
each step below, called in turn (a, b, c, d, a, b, ...) so that a passing load falls on all of them:
  * FLIP's fused step called once per step (``FusedStep.step``, one thread);
  * APIC's fused step, the same call (its two kernels: P2G's affine term, G2P's ``C_p``;
    :mod:`mpm_fem.core.transfers.apic`), with the particles' ``C_p`` nonzero;
  * APIC's and FLIP's numpy steps (:func:`mpm_fem.core.step.explicit_step`).
Printed: particle-steps per second of each, and the ratios APIC fused / FLIP fused (what the affine
kernels cost) and APIC numpy / APIC fused (what they buy). CPU time of this process: the machines are
shared. Usage: ``python benchmarks/transfer_cost.py [--sizes 1e4,1e5,1e6] [--repeat 5]``.
"""

from __future__ import annotations

import argparse

import numpy as np
from step_cost import interleaved, setup  # benchmarks/step_cost.py, beside this script

from mpm_fem.core.step import Stages, Walls, explicit_step
from mpm_fem.fused.step import FusedStep


def measure(n_particles: int, repeat: int) -> dict:
    grid, particles, gas, dt = setup(n_particles)
    particles = particles.replace(affine=np.sin(7.0 * particles.x))  # an affine part to carry
    steps = {}
    for name in ("flip", "apic"):
        stages = Stages(transfer=name)
        fused = FusedStep(grid, gas, Walls(), stages, reuse=True)
        fused.step(particles, 0.0, dt)  # compile (or load the cache) and fill the buffers
        steps[f"{name} fused"] = (lambda f=fused: f.step(particles, 0.0, dt))
        steps[f"{name} numpy"] = (lambda s=stages: explicit_step(grid, particles, gas, Walls(), 0.0, dt, s))
    times = dict(zip(steps, interleaved(list(steps.values()), repeat), strict=True))
    n = particles.n
    return {"n_p": n, **{f"{k} rate": n / t for k, t in times.items()},
            "apic / flip (fused)": times["apic fused"] / times["flip fused"],
            "numpy / fused (apic)": times["apic numpy"] / times["apic fused"]}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1e4,1e5,1e6", help="particle counts, comma-separated")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    sizes = [int(float(s)) for s in args.sizes.split(",")]
    rows = [measure(n, args.repeat) for n in sizes]
    keys = [k for k in rows[0] if k != "n_p"]
    print("| particles | " + " | ".join(keys) + " |")
    print("|---:|" + "---:|" * len(keys))
    for r in rows:
        print(f"| {r['n_p']:.0e} | " + " | ".join(f"{r[k]:.3g}" for k in keys) + " |")


if __name__ == "__main__":
    main()
