"""What calling a static solve from Python costs over calling it from Rust, on the pinned
elastica (`planning_cases/pinned_buckling_080.json`).

    python python/benches/static_call.py [--repeats 300]

Both sides run the same compiled code in one process: `_dlo.solve_repeatedly` times, in Rust,
a solve of the built problem from its natural start with its report (what `dlo shape`
computes); the Python side times `StaticProblem.solve`, which also builds the problem,
releases the GIL, and returns the report as a `StaticShape` with NumPy arrays (the shape at
the quadrature mesh's boundaries by default, or at `points` evenly spaced arc lengths).
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
    problem = dlo.StaticProblem(rod).position(100.0, name="right pin", equal={"x": 0.0, "z": 80.0})

    def python(points):
        times = []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            problem.solve(points=points)
            times.append(time.perf_counter() - t0)
        return statistics.median(times)

    sides = {
        "Rust": lambda: statistics.median(_dlo.solve_repeatedly(problem, args.repeats)),
        "Python": lambda: python(None),
        "Python, points=101": lambda: python(101),
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
