"""Cost of each grid mass per 2D step, as ratios to the lumped step in the same run.

The case: the axis-aligned solid (A = 1e-4) on the periodic square ``[0, 2)^2``, 2 x 2 regular
particles per cell, USL, FLIP, the body force, the numpy step (:func:`mpm_fem.plane.step.step_with_grid`:
every mass runs there; the compiled step serves the lumped mass only), the basis ``--basis``. At each
mesh (``--cells`` per axis) a batch of ``--steps`` steps of every mass of the registry
(:func:`mpm_fem.masses.names`) but ``exact`` (which needs the exact stages) alternates with the
others ``--repeat`` times (a load that comes and goes on a shared machine falls on all of them) and
the best batch of each is kept (CPU time of this process). Printed: the seconds per step of each
mass, and its ratio to the lumped step of the same mesh. The ``grid`` mass's factor (built once per
grid) is made before the timing, as a run makes it once. Usage:
``python benchmarks/mass_cost.py [--cells 32 64 128] [--steps 5] [--repeat 3] [--basis mpm]``.
"""

from __future__ import annotations

import argparse
import sys

from step_cost import interleaved  # benchmarks/step_cost.py, beside this script

import mpm_fem.masses as masses
from mpm_fem.plane.problems import start
from mpm_fem.plane.run import PlaneSettings, setup
from mpm_fem.plane.step import step_with_grid

PPC, AMPLITUDE, CFL = 2, 1e-4, 0.25


def batch(cells: int, mass: str, basis: str, steps: int):
    """A callable running ``steps`` numpy steps of ``mass`` from the start of the ``cells``^2 case (each
    call from the same start), the particle count."""
    s = PlaneSettings(h=2.0 / cells, ppc=PPC, amplitude=AMPLITUDE, cfl=CFL, basis=basis, mass=mass)
    solution, grid, (X, V0, lengths), _ = setup(s)
    dt = CFL * min(grid.h) / solution.material.c
    first = start(solution, X, V0, lengths, dt)
    stages = s.stages

    def loop():
        state = first
        for n in range(steps):
            state = step_with_grid(state, grid, basis, solution.material, dt, n * dt, solution.body_force, stages,
                                   None, mass)[0]

    if mass == "grid":
        step_with_grid(first, grid, basis, solution.material, dt, 0.0, solution.body_force, stages, None, mass)
    return loop, X.shape[0]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cells", type=int, nargs="+", default=[32, 64, 128])
    parser.add_argument("--steps", type=int, default=5)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--basis", default="mpm")
    args = parser.parse_args(argv)
    if min(args.cells) < 4 or args.steps < 1 or args.repeat < 1:
        print("mass_cost.py: --cells >= 4, --steps >= 1, --repeat >= 1", file=sys.stderr)
        return 2
    names = [m for m in masses.names() if m != "exact"]
    print(f"2D step per grid mass ({args.basis}, 2 x 2 per cell, numpy step): seconds per step, ratio to lumped\n")
    print("| cells | particles | " + " | ".join(names) + " |")
    print("|---|---|" + "---|" * len(names))
    for cells in args.cells:
        loops = [batch(cells, m, args.basis, args.steps) for m in names]
        best = interleaved([fn for fn, _ in loops], args.repeat)
        per_step = [b / args.steps for b in best]
        lumped = per_step[names.index("lumped")]
        cells_text = " | ".join(f"{t:.3g} s ({t / lumped:.2f}x)" for t in per_step)
        print(f"| {cells}^2 | {loops[0][1]} | {cells_text} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
