"""A parameter sweep of static shapes on Ray: the pinned elastica (L = 100, Rf = 1, both ends
pinned on the z axis) over chord ratios l/L and lengths, in one batch per CPU, each solved by
a Ray actor that stays warm between sweeps (plain tasks, `on_ray(params, batches)`, work too).

    python python/examples/ray_sweep.py --shapes 1000 --workers 2      # a local Ray
    python python/examples/ray_sweep.py --shapes 1000 --compare        # and the serial loop

On a cluster, start Ray on its machines (`ray start --head` on one, `ray start
--address=HEAD:6379` on the others), install the package on each (`pip install ./python`),
and run the same command on the head node with `--address auto` (or set `RAY_ADDRESS`):
nothing else changes. Without Ray, `dlo shape CASE.json` runs one case per process under any
job array (Slurm, PBS, GNU parallel).
"""

from __future__ import annotations

import argparse
import time

import dlo_planner as dlo


def parameters(n: int) -> list[tuple[float, float]]:
    """`n` (chord ratio, length) pairs: ratios 0.30 … 0.95 across lengths 50 … 150."""
    lengths = [50.0, 75.0, 100.0, 125.0, 150.0]
    per = -(-n // len(lengths))
    ratios = [0.30 + 0.65 * i / max(per - 1, 1) for i in range(per)]
    return [(r, l) for l in lengths for r in ratios][:n]


def solve(ratio: float, length: float) -> tuple[float, float, float, str]:
    """The pinned elastica of chord `ratio · length`: (force at the pin, energy, sag, status)."""
    rod = dlo.Rod(length=length, flexural_rigidity=1.0, radius=length / 2000)
    problem = dlo.StaticProblem(rod).position(length, name="pin", equal={"x": 0.0, "z": ratio * length})
    shape = problem.solve(points=21)
    pin = [r for r in shape.reactions if r.constraint == "pin"][0]
    sag = float(abs(shape.positions[:, 0]).max())
    return (pin.force[2], shape.energy.total, sag, shape.status)


def solve_batch(batch: list[tuple[float, float]]) -> list[tuple[float, float, float, str]]:
    return [solve(r, l) for r, l in batch]


def serial(params: list[tuple[float, float]]) -> list[tuple[float, float, float, str]]:
    return solve_batch(params)


def on_ray(params: list[tuple[float, float]], batches: int, workers: list | None = None) -> list[tuple[float, float, float, str]]:
    """The sweep as `batches` Ray tasks, results in the order of `params`; on `workers`
    (actors from `solvers`, which keep their imports warm) when given."""
    import ray

    # Batch j takes every `batches`-th parameter from the j-th: each spans the sweep's whole
    # range (short rods and long), so that the batches take about the same time.
    batches = max(1, min(batches, len(params)))
    parts = [params[j::batches] for j in range(batches)]
    if workers:
        refs = [workers[i % len(workers)].solve_batch.remote(p) for i, p in enumerate(parts)]
    else:
        task = ray.remote(solve_batch)
        refs = [task.remote(p) for p in parts]
    rows: list = [None] * len(params)
    for j, part in enumerate(ray.get(refs)):
        rows[j::batches] = part
    return rows


class Solver:
    """A Ray actor that solves batches: one per CPU, started once."""

    def solve_batch(self, batch: list[tuple[float, float]]) -> list[tuple[float, float, float, str]]:
        return solve_batch(batch)


def solvers(n: int) -> list:
    """`n` warm solver actors."""
    import ray

    actors = [ray.remote(num_cpus=1)(Solver).remote() for _ in range(n)]
    ray.get([a.solve_batch.remote([(0.5, 100.0)]) for a in actors])
    return actors


def start_ray(workers: int, address: str | None):
    import ray

    if address:
        ray.init(address=address)
    else:
        ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
    return ray


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--shapes", type=int, default=1000)
    ap.add_argument("--workers", type=int, default=2, help="CPUs of a local Ray")
    ap.add_argument("--address", default=None, help="a running Ray cluster (e.g. auto)")
    ap.add_argument("--batches", type=int, default=None, help="tasks (default one per CPU)")
    ap.add_argument("--compare", action="store_true", help="also run the serial loop and compare")
    ap.add_argument("--repeats", type=int, default=5, help="timed runs of each; the fastest counts")
    args = ap.parse_args()
    params = parameters(args.shapes)
    ray = start_ray(args.workers, args.address)
    cpus = int(ray.cluster_resources().get("CPU", args.workers))
    batches = args.batches or cpus
    workers = solvers(cpus)
    # With --compare, Ray and the serial loop take turns, so that both meet the machine's
    # speed of the moment alike.
    t_ray, t_serial, reference = float("inf"), float("inf"), None
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        rows = on_ray(params, batches, workers)
        t_ray = min(t_ray, time.perf_counter() - t0)
        if args.compare:
            t0 = time.perf_counter()
            reference = serial(params)
            t_serial = min(t_serial, time.perf_counter() - t0)
    converged = sum(r[3] == "converged" for r in rows)
    print(f"ray: {len(rows)} shapes on {cpus} CPUs in {t_ray:.3f} s ({converged} converged)")
    if args.compare:
        same = reference == rows
        print(f"serial: {t_serial:.3f} s; ray/serial = {t_ray / t_serial:.3f}; identical results: {same}")
    ray.shutdown()


if __name__ == "__main__":
    main()
