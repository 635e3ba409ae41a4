"""Results: the JSON reports the ``dlo`` command prints (``--json``), with their keys as
attributes, and NumPy arrays of the shapes and the gripper trajectory.

Every result is plain Python (picklable: it crosses process pools and Ray tasks).
"""

from __future__ import annotations

import copy
import json
from typing import Any, Iterator

import numpy as np


def _wrap(value: Any) -> Any:
    if isinstance(value, dict):
        return Report(value)
    if isinstance(value, list):
        return [_wrap(v) for v in value]
    return value


class Report:
    """A JSON report (or part of one) whose keys read as attributes: ``r.energy.total`` is
    ``r.to_dict()["energy"]["total"]``. ``r["key"]`` and ``"key" in r`` work too. Given as
    JSON text, it is parsed when first read."""

    def __init__(self, data: "dict | str"):
        if isinstance(data, str):
            self._text = data
        else:
            self._data = data

    def __getattr__(self, name: str) -> Any:
        if name == "_data":
            self._data = json.loads(self.__dict__.pop("_text"))
            return self._data
        if name.startswith("__") or name == "_text":
            raise AttributeError(name)
        try:
            return _wrap(self._data[name])
        except KeyError:
            raise AttributeError(
                f"{type(self).__name__} has no field {name!r}; fields: {', '.join(self._data)}"
            ) from None

    def __getitem__(self, key: str) -> Any:
        return _wrap(self._data[key])

    def __contains__(self, key: object) -> bool:
        return key in self._data

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def keys(self):
        return self._data.keys()

    def to_dict(self) -> dict:
        """The report as a dict (a copy): what ``dlo … --json`` prints."""
        return copy.deepcopy(self._data)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Report) and self._data == other._data

    def __repr__(self) -> str:
        text = json.dumps(self._data)
        return f"{type(self).__name__}({text[:200]}{'…' if len(text) > 200 else ''})"

    def __getstate__(self) -> dict:
        self._data  # parsed, so that the state is the dict
        return self.__dict__.copy()

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)


class StaticShape(Report):
    """A static shape: the report of ``dlo shape --json`` (``status``, ``energy``,
    ``reactions``, ``balance``, ``stable``, ``end_pose``, ``coefficients`` by field, …) and the
    shape sampled along the rod.

    Attributes:
        a: the Ritz coefficients (NumPy vector), as ``StaticProblem.solve(initial=…)`` and
            ``End.shape`` take them.
        s: arc lengths of the samples, evenly spaced over ``[0, L]``.
        positions: positions at ``s`` (``len(s) × 3``).
        frames: cross-section frames at ``s`` (``len(s) × 3 × 3``; columns ξ, η and the
            tangent ζ).
    """

    def __init__(self, report: str, a, samples):
        super().__init__(report)
        # The core's sampler, asked for the arrays when they are first read.
        self._raw = (a, samples)

    def _arrays(self) -> None:
        a, samples = self.__dict__.pop("_raw")
        s, positions, frames = samples.arrays()
        self.a = np.asarray(a, dtype=float)
        self.s = np.asarray(s, dtype=float)
        self.positions = np.asarray(positions, dtype=float).reshape(-1, 3)
        self.frames = np.asarray(frames, dtype=float).reshape(-1, 3, 3)

    def __getattr__(self, name: str) -> Any:
        if name in ("a", "s", "positions", "frames") and "_raw" in self.__dict__:
            self._arrays()
            return self.__dict__[name]
        return super().__getattr__(name)

    def __getstate__(self) -> dict:
        if "_raw" in self.__dict__:
            self._arrays()
        return super().__getstate__()

    @property
    def converged(self) -> bool:
        """Whether the solve converged (an evaluation is not a solve: ``False``)."""
        return self._data["status"] == "converged"


class Trajectory(Report):
    """The controlled end's poses along a plan (the report's ``trajectory``), as arrays.

    Attributes:
        k: path parameter of each pose.
        positions: ``len(k) × 3`` positions (case frame).
        quaternions: ``len(k) × 4`` unit quaternions ``(w, x, y, z)``, continuous in sign.
        rotations: ``len(k) × 3 × 3`` rotation matrices (columns ξ, η, ζ).
        time_s: times (s) of a time-parameterised trajectory, else ``None``.
    """

    def __init__(self, data: dict):
        super().__init__(data)
        poses = data["poses"]
        self.k = np.array([p["k"] for p in poses], dtype=float)
        self.positions = np.array([p["position"] for p in poses], dtype=float).reshape(-1, 3)
        self.quaternions = np.array([p["quaternion"] for p in poses], dtype=float).reshape(-1, 4)
        self.rotations = np.array([p["rotation"] for p in poses], dtype=float).reshape(-1, 3, 3)
        times = [p.get("time_s") for p in poses]
        self.time_s = np.array(times, dtype=float) if poses and None not in times else None


class Shapes:
    """Shapes along a plan: ``k`` (increasing) and ``positions`` (``len(k) × points × 3``, the
    rod at the quadrature mesh's boundaries, case units)."""

    def __init__(self, k, positions):
        self.k = np.asarray(k, dtype=float)
        x = np.asarray(positions, dtype=float)
        self.positions = x.reshape(len(self.k), -1, 3) if len(self.k) else x.reshape(0, 0, 3)

    def __len__(self) -> int:
        return len(self.k)

    def __repr__(self) -> str:
        return f"Shapes({len(self.k)} shapes of {self.positions.shape[1]} points)"


class Plan(Report):
    """A plan: the report of ``dlo plan --json`` (``verdict``, ``executed_path``, ``status``,
    ``u_max``, ``replay``, ``equilibrium_plan``, ``verification``, ``starts``, ``path``,
    ``trajectory``, …).

    Attributes:
        gripper: the controlled end's trajectory as arrays (:class:`Trajectory`).
        path: the path vectors ``c_i`` (``m × n`` array) of ``a(c, k)``.
        planned: the planned shapes at the replay's steps (:class:`Shapes`; empty when the run
            stopped before the replay).
        replayed: the shapes the controlled end's motion produces there (:class:`Shapes`).
    """

    def __init__(self, report: str, planned=((), ()), replayed=((), ())):
        super().__init__(json.loads(report))
        self.planned = Shapes(*planned)
        self.replayed = Shapes(*replayed)
        self.gripper = Trajectory(self._data["trajectory"])
        self.path = np.asarray(self._data["path"], dtype=float)

    @property
    def executable(self) -> bool:
        """Whether the gripper trajectory executes a collision-free plan: the optimal path,
        whose replay coincides with it, or its replayed equilibria (``executed_path`` says
        which)."""
        return self._data["verdict"] == "executable"


class Margin(Report):
    """A grasp's disturbance force margin: the report of ``dlo margin --json`` (``mu``,
    ``f_mub``, ``s_a``, ``direction``, ``capped``, ``f_max``, ``initial_forces``, ``table``).

    Attributes:
        mu, f_mub: the margin curve as NumPy vectors.
    """

    def __init__(self, report: str):
        super().__init__(json.loads(report))
        self.mu = np.asarray(self._data["mu"], dtype=float)
        self.f_mub = np.asarray(self._data["f_mub"], dtype=float)
