#!/usr/bin/env python3
"""Reads a gripper trajectory CSV (`dlo plan`'s `<case>.trajectory.csv`) with Python's standard
csv module and checks it: the documented header, one row per replay step in increasing k,
finite numbers, unit quaternions that match their rotation matrices, no quaternion sign flips
between rows. Exit code 1 on any problem."""
import csv
import math
import sys


def quat_matrix(w, x, y, z):
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]


def check(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise SystemExit(f"{path}: no rows")
    cols = list(rows[0].keys())
    pos = [c for c in cols if c.split(" ")[0] in ("x", "y", "z")]
    need = ["k", "qw", "qx", "qy", "qz"] + [f"r{i}{j}" for i in range(3) for j in range(3)]
    missing = [c for c in need if c not in cols]
    if missing or len(pos) != 3:
        raise SystemExit(f"{path}: header lacks {missing or 'x, y, z'}: {cols}")
    prev_k, prev_q = -1.0, None
    for i, r in enumerate(rows):
        v = {c: float(r[c]) for c in cols}
        if not all(math.isfinite(x) for x in v.values()):
            raise SystemExit(f"{path}: row {i}: not finite")
        if v["k"] <= prev_k:
            raise SystemExit(f"{path}: row {i}: k does not increase")
        q = [v["qw"], v["qx"], v["qy"], v["qz"]]
        if abs(math.sqrt(sum(c * c for c in q)) - 1) > 1e-12:
            raise SystemExit(f"{path}: row {i}: quaternion not unit")
        m = quat_matrix(*q)
        err = max(abs(m[a][b] - v[f"r{a}{b}"]) for a in range(3) for b in range(3))
        if err > 1e-12:
            raise SystemExit(f"{path}: row {i}: quaternion and matrix differ by {err}")
        if prev_q is not None and sum(a * b for a, b in zip(q, prev_q)) < 0:
            raise SystemExit(f"{path}: row {i}: quaternion flips sign")
        prev_k, prev_q = v["k"], q
    print(f"{path}: {len(rows)} poses, columns {len(cols)}: ok")


for p in sys.argv[1:]:
    check(p)
