"""What calling a static solve from Python costs over calling it from Rust, on the pinned
elastica (`planning_cases/pinned_buckling_080.json`).

    python python/benches/static_call.py [--repeats 300]

Both sides run the same compiled code in one process: `_dlo.solve_repeatedly` times, in Rust,
a solve of the built problem from its natural start with its report (what `dlo shape`
computes); the Python side times `StaticProblem.solve`, which also builds the problem,
releases the GIL, and returns a `StaticShape`, whose report is parsed and whose shape is sampled
(at the quadrature mesh's boundaries, or at `points` evenly spaced arc lengths) when first
read: the second and third rows read the energy and the positions too.
Each side's median over `--repeats` solves, the fastest of `--rounds` alternating rounds.
"""

import argparse
import statistics
import time

import dlo_planner as dlo
from dlo_planner import _dlo


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=100, help="solves per round and side")
    ap.add_argument("--rounds", type=int, default=7, help="rounds, alternating the sides")
    args = ap.parse_args()
    rod = dlo.Rod(length=100.0, flexural_rigidity=1.0, radius=0.05)
    problem = dlo.StaticProblem(rod, basis="paper").position(100.0, name="right pin", equal={"x": 0.0, "z": 80.0})

    def python(points, read):
        times = []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            shape = problem.solve(points=points)
            if read:
                shape.energy.total, shape.positions
            times.append(time.perf_counter() - t0)
        return statistics.median(times)

    sides = {
        "Rust": lambda: statistics.median(_dlo.solve_repeatedly(problem, args.repeats)),
        "Python": lambda: python(None, False),
        "+ energy, positions": lambda: python(None, True),
        "+ 101 points": lambda: python(101, True),
    }
    # The machine's speed drifts: alternate the sides and keep each one's fastest round.
    best = {name: float("inf") for name in sides}
    for _ in range(args.rounds):
        for name, run in sides.items():
            best[name] = min(best[name], run())
    rust = best["Rust"]
    for name, t in best.items():
        extra = "" if name == "Rust" else f": {100 * (t / rust - 1):+.1f} %"
        print(f"{name:20} {t * 1e3:.3f} ms per solve{extra}")


if __name__ == "__main__":
    main()
