"""Two plans in two Python threads at once against the same two one after the other: every
plan releases the GIL, so on two cores the threads share the work.

    python python/benches/two_threads.py [--rounds 5]

The plan is the README's, built in code (a strip under a block, swung from side to side), with
one thread of its own per plan (`threads: 1`), so that one plan alone keeps one core busy.
The two ways take turns, `--rounds` times each; the fastest run of each counts.
"""

import argparse
import math
import threading
import time

import dlo_planner as dlo


def block_problem() -> tuple:
    rod = dlo.Rod(length=1.0, flexural_rigidity=1.0, radius=0.005)
    block = dlo.Obstacle.cuboid("block", [0.1, 0.5, 0.25], position=[0.0, 0.0, 1.1])
    held = dlo.StaticProblem(rod).clamp(0.0, [0, 0, 0], [0.0]).obstacle(block)
    turn = lambda t: [[math.cos(t), 0, math.sin(t)], [0, 1, 0], [-math.sin(t), 0, math.cos(t)]]  # noqa: E731
    start = dlo.End.pose([0.5, 0.0, 0.6], rotation=turn(math.pi / 2))
    goal = dlo.End.pose([-0.5, 0.0, 0.6], rotation=turn(-math.pi / 2))
    return held, start, goal


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
