"""Two plans in two Python threads at once against the same two one after the other: every
plan releases the GIL, so on two cores the threads share the work.

    python python/benches/two_threads.py [--rounds 5]

The plan is the README's, built in code as `python/tests/test_plan.py` builds it (a strip under
a block, swung from side to side; the bench imports it from there, with pytest installed), with
one thread of its own per plan (`threads: 1`), so that one plan alone keeps one core busy. The
two ways take turns, `--rounds` times each; the fastest run of each counts.
"""

import argparse
import math
import sys
import threading
import time
from pathlib import Path

import dlo_planner as dlo

# The plan of the package's tests (`block_problem`), so that both use one problem.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_plan import block_problem  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=5, help="runs of each way, taking turns")
    args = ap.parse_args()
    held, start, goal = block_problem()
    settings = {"starts": 1, "threads": 1}

    def serial():
        for _ in range(2):
            dlo.plan(held, start, goal, settings=settings)

    def at_once():
        threads = [threading.Thread(target=lambda: dlo.plan(held, start, goal, settings=settings)) for _ in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()

    best = {"one after the other": math.inf, "at once": math.inf}
    for _ in range(args.rounds):
        for name, run in (("one after the other", serial), ("at once", at_once)):
            t0 = time.perf_counter()
            run()
            best[name] = min(best[name], time.perf_counter() - t0)
    a, b = best["one after the other"], best["at once"]
    print(f"two plans one after the other {a:.3f} s, at once {b:.3f} s: {b / a:.2f} ×")


if __name__ == "__main__":
    main()
