"""Cost of one MPM step of Sod's tube as the particle count grows.

Reports, for n_p = 1e3 ... 1e6 (add --max 1e7 where memory allows):
  * particle-steps per second of the full step (``mpm_fem.step.explicit_step``, USL, lumped);
  * the ratio of the full step to the bare numpy transfers it needs, timed in the same run:
    the three ``np.bincount`` scatters (mass, momentum, force) and the three gathers
    (acceleration, velocity, velocity gradient) on the same particles;
  * memory per particle: the particle state plus the peak allocated during one step (tracemalloc).
and the log-log slope of time against n_p (1.0 = linear). Ratios, not wall times, are the result:
the machines are shared and noisy. Usage: ``python benchmarks/step_cost.py [--max 1e6] [--repeat 5]``.
"""

from __future__ import annotations

import argparse
import time
import tracemalloc

import numpy as np

from mpm_fem.problems.sod import SodSettings, initial_particles
from mpm_fem.grid import uniform_grid
from mpm_fem.models.euler import IdealGas
from mpm_fem.step import Stages, Walls, explicit_step


def bare_transfers(nodes, S, G, q, f, n_nodes):
    """What any MPM step must do: 3 scatters and 3 gathers of the compact (n_p, 2) kernel."""
    flat, n0, n1 = nodes.ravel(), nodes[:, 0], nodes[:, 1]
    m = np.bincount(flat, (S * q[:, None]).ravel(), n_nodes)
    P = np.bincount(flat, (S * (q * f[n0])[:, None]).ravel(), n_nodes)
    F = np.bincount(flat, (G * q[:, None]).ravel(), n_nodes)
    a = S[:, 0] * F[n0] + S[:, 1] * F[n1]
    v = S[:, 0] * P[n0] + S[:, 1] * P[n1]
    L = G[:, 0] * m[n0] + G[:, 1] * m[n1]
    return a, v, L


def best_time(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def measure(n_particles: int, repeat: int) -> dict:
    ppc = 8
    n_cells = max(2, n_particles // ppc)
    h = 1.0 / n_cells
    settings = SodSettings(h=h, ppc=ppc)
    grid = uniform_grid(0.0, 1.0, h)
    particles = initial_particles(settings, grid)
    gas, walls, stages = IdealGas(), Walls(), Stages()
    dt = 0.1 * gas.stable_dt(particles, grid, 1.0)
    full = best_time(lambda: explicit_step(grid, particles, gas, walls, 0.0, dt, stages), repeat)

    from mpm_fem.shape import point_shape

    shape = point_shape(grid, particles.x)
    f = np.ones(grid.n_nodes)
    bare = best_time(lambda: bare_transfers(shape.nodes, shape.S, shape.G, particles.mass, f, grid.n_nodes), repeat)

    tracemalloc.start()
    explicit_step(grid, particles, gas, walls, 0.0, dt, stages)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    n = particles.n
    state = sum(getattr(particles, name).nbytes for name in ("x", "volume", "mass", "velocity", "density", "energy", "pressure"))
    return {"n_p": n, "full_s": full, "bare_s": bare, "ratio": full / bare, "rate": n / full,
            "bytes_per_particle": (state + peak) / n}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max", type=float, default=1e6, help="largest particle count (default 1e6)")
    parser.add_argument("--repeat", type=int, default=5, help="timings per size; the best is kept")
    args = parser.parse_args(argv)
    sizes = [int(10**k) for k in np.arange(3, np.log10(args.max) + 0.01, 0.5)]
    rows = [measure(n, args.repeat if n <= 10**6 else 2) for n in sizes]
    print("| particles | particle-steps/s | full step / bare transfers | bytes per particle (state + step peak) |")
    print("|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['n_p']:.0e} | {r['rate']:.3g} | {r['ratio']:.2f} | {r['bytes_per_particle']:.0f} |")
    n = np.array([r["n_p"] for r in rows], float)
    t = np.array([r["full_s"] for r in rows])
    big = n >= 1e4  # below that, fixed per-call overhead dominates
    slope = np.polyfit(np.log(n[big]), np.log(t[big]), 1)[0] if big.sum() >= 2 else float("nan")
    print(f"\nlog-log slope of step time against n_p (n_p >= 1e4): {slope:.3f} (1.0 = linear)")


if __name__ == "__main__":
    main()
