"""What calling a static solve from Python costs over calling it from Rust, on the pinned
elastica (`planning_cases/pinned_buckling_080.json`).

    python python/benches/static_call.py [--repeats 300]

Both sides run the same compiled code in one process: `_dlo.solve_repeatedly` times, in Rust,
a solve of the built problem from its natural start with its report (what `dlo shape`
computes); the Python side times `StaticProblem.solve`, which also builds the problem,
releases the GIL, and returns the report as a `StaticShape` with NumPy arrays (the shape at
the quadrature mesh's boundaries by default, or at `points` evenly spaced arc lengths).
Medians of the repeats.
"""

import argparse
import statistics
import time

import dlo_planner as dlo
from dlo_planner import _dlo


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=300)
    args = ap.parse_args()
    rod = dlo.Rod(length=100.0, flexural_rigidity=1.0, radius=0.05)
    problem = dlo.StaticProblem(rod).position(100.0, name="right pin", equal={"x": 0.0, "z": 80.0})
    rust = statistics.median(_dlo.solve_repeatedly(problem, args.repeats))
    print(f"Rust:   {rust * 1e3:.3f} ms per solve (median of {args.repeats})")
    for points in (None, 101):
        problem.solve(points=points)
        times = []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            problem.solve(points=points)
            times.append(time.perf_counter() - t0)
        py = statistics.median(times)
        print(f"Python: {py * 1e3:.3f} ms per solve, points={points}: {100 * (py / rust - 1):+.1f} %")


if __name__ == "__main__":
    main()
