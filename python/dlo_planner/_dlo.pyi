"""Type stubs of the Rust core of :mod:`dlo_planner` (see the package for the overview)."""

from os import PathLike
from typing import Any, Callable, Literal, Mapping, Optional, Sequence, Union

from .results import Margin, Plan, StaticShape

__version__: str

Vec3 = Sequence[float]
Matrix3 = Sequence[Sequence[float]]
Path = Union[str, PathLike]
Settings = Mapping[str, Any]
#: ``progress(event, info)``: ``event`` is ``"phase"`` (``info["name"]``), ``"iteration"``
#: (start, stage, outer, smoothed_max, sampled_max, k_worst, violation, rho), ``"replay"``
#: (k, deviation, energy) or ``"margin"`` (done, total). Returning ``True`` stops a plan (its
#: verdict is then ``"interrupted"``); raising stops it and the exception propagates.
Progress = Callable[[str, dict], Optional[bool]]

class InputError(ValueError):
    """Bad input. ``field`` names the field (``None`` when the input could not be parsed far
    enough to name one); ``message`` says what is wrong."""

    field: Optional[str]
    message: str

class UnreachableError(InputError):
    """No static shape reaches a plan's start or goal (``field``): nothing was planned."""

class Rod:
    """A uniform rod in consistent units. A rod with ``torsional_rigidity`` is 3D; without, it
    is planar (it lies in the x–z plane). ``radius`` defaults to ``length / 1000``. Gravity acts
    along −x."""

    def __init__(
        self,
        length: float,
        flexural_rigidity: float,
        torsional_rigidity: Optional[float] = None,
        extensional_rigidity: Optional[float] = None,
        weight_per_length: float = 0.0,
        radius: Optional[float] = None,
    ) -> None: ...
    @property
    def length(self) -> float: ...
    @property
    def spatial(self) -> bool: ...
    @property
    def radius(self) -> float: ...

class Obstacle:
    """A rigid obstacle placed at ``position`` and turned by the axis-angle vector
    ``rotation`` (radians)."""

    @staticmethod
    def ball(name: str, radius: float, position: Vec3, rotation: Vec3 = ...) -> Obstacle: ...
    @staticmethod
    def cuboid(name: str, half_extents: Vec3, position: Vec3, rotation: Vec3 = ...) -> Obstacle: ...
    @staticmethod
    def cylinder(
        name: str, half_height: float, radius: float, position: Vec3, rotation: Vec3 = ...
    ) -> Obstacle:
        """A cylinder whose axis runs along its local y."""
    @staticmethod
    def capsule(
        name: str, a: Vec3, b: Vec3, radius: float, position: Vec3 = ..., rotation: Vec3 = ...
    ) -> Obstacle:
        """The points within ``radius`` of the segment from ``a`` to ``b``."""
    @staticmethod
    def convex_hull(
        name: str, points: Sequence[Vec3], position: Vec3 = ..., rotation: Vec3 = ...
    ) -> Obstacle:
        """The convex hull of at least 4 points spanning a volume."""
    @staticmethod
    def half_space(name: str, normal: Vec3, position: Vec3 = ..., rotation: Vec3 = ...) -> Obstacle:
        """The points behind the plane through ``position`` with outward ``normal``."""
    @staticmethod
    def mesh(
        name: str,
        vertices: Sequence[Vec3],
        triangles: Sequence[Sequence[int]],
        position: Vec3 = ...,
        rotation: Vec3 = ...,
    ) -> Obstacle:
        """A closed triangle mesh (e.g. NumPy ``n × 3`` vertices and ``m × 3`` indices), faces
        counter-clockwise seen from outside; an open, inside-out or flat mesh is an
        :class:`InputError` on ``triangles``."""
    @property
    def name(self) -> str: ...
    def signed_distance(self, point: Vec3) -> tuple[list[float], float]:
        """The outward normal at the nearest surface point and the signed distance (negative
        inside)."""

class StaticProblem:
    """A rod's static problem: conditions at arc lengths, loads, obstacles, self-contact.
    Methods that add to it return the problem, so calls chain. ``basis`` is ``"legendre"`` (the
    default: ``1, s/L`` and Legendre polynomials in ``s/L``) or ``"paper"`` (the paper's ``1,
    s/L, sin, cos``); ``contact`` is where obstacle contacts are
    held: ``"points"`` (the sample points) or ``"chords"`` (the chords between them)."""

    def __init__(
        self,
        rod: Rod,
        basis_pairs: int = 4,
        basis: Literal["paper", "legendre"] = "legendre",
        panels: int = 16,
        gauss_points: int = 4,
        samples: int = 32,
        base: Vec3 = ...,
        free_base: bool = False,
        contact: Literal["points", "chords"] = "points",
    ) -> None: ...
    def clamp(self, s: float, position: Vec3, angles: Sequence[float]) -> StaticProblem:
        """Clamps the rod at ``s``: the point at ``position`` and the Euler angles — ``[θ]``
        planar, ``[φ, θ, ψ]`` (ZYZ) in 3D."""
    def fix_point(self, s: float, position: Vec3) -> StaticProblem: ...
    def position(
        self,
        s: float,
        name: Optional[str] = None,
        equal: Optional[Mapping[str, float]] = None,
        at_least: Optional[Mapping[str, float]] = None,
        at_most: Optional[Mapping[str, float]] = None,
    ) -> StaticProblem:
        """Conditions on the position at ``s`` by axis (``"x"``, ``"y"``, ``"z"``); a finger of a
        grasp is a position with one bound."""
    def orientation(
        self,
        s: float,
        phi: Optional[float] = None,
        theta: Optional[float] = None,
        psi: Optional[float] = None,
    ) -> StaticProblem: ...
    def load(self, s: float, force: Vec3, reference: Vec3 = ...) -> StaticProblem: ...
    def obstacle(self, obstacle: Obstacle, margin: float = 0.0) -> StaticProblem: ...
    def self_contact(self, on: bool = True) -> StaticProblem: ...
    @property
    def spatial(self) -> bool: ...
    @property
    def coefficients(self) -> int:
        """Number of Ritz coefficients."""
    def solve(
        self,
        initial: Optional[Sequence[float]] = None,
        settings: Optional[Settings] = None,
        report_points: Optional[Sequence[float]] = None,
        points: Optional[int] = None,
        log_dir: Optional[Path] = None,
        name: str = "shape",
    ) -> StaticShape:
        """The static shape, from ``initial`` coefficients or the natural state. ``settings``
        takes a case file's ``solver`` keys. The shape is sampled at the quadrature mesh's
        boundaries, or at ``points`` evenly spaced arc lengths. With ``log_dir`` it is logged
        to ``log_dir/<name>.mcap`` as ``dlo shape`` logs it."""
    def evaluate(
        self,
        coefficients: Sequence[float],
        report_points: Optional[Sequence[float]] = None,
        points: Optional[int] = None,
        name: str = "shape",
    ) -> StaticShape:
        """Energy, reactions and violation of given coefficients without optimising."""

class End:
    """Where the controlled end (``s = L``) starts or goes."""

    @staticmethod
    def pose(
        position: Vec3,
        rotation: Optional[Matrix3] = None,
        quaternion: Optional[Sequence[float]] = None,
        angles: Optional[Sequence[float]] = None,
    ) -> End:
        """A pose: position and orientation as a rotation matrix (rows; columns ξ, η and the
        tangent ζ), a unit quaternion ``(w, x, y, z)`` or Euler angles as a case file writes
        them (``[theta]`` planar, kept as written; ``[phi, theta, psi]`` 3D, in the branch
        nearest the written ``phi``); with none, the orientation is left free."""
    @staticmethod
    def shape(coefficients: Sequence[float]) -> End:
        """A shape given by its coefficients (``StaticShape.a``)."""

class Case:
    """A case file, read and validated; its runs are the CLI's."""

    @staticmethod
    def load(path: Path) -> Case: ...
    @staticmethod
    def parse(text: str, path: Optional[Path] = None) -> Case: ...
    @property
    def name(self) -> str: ...
    @property
    def description(self) -> str: ...
    @property
    def warnings(self) -> list[str]: ...
    @property
    def problem(self) -> StaticProblem: ...
    def solve(self, points: Optional[int] = None, log_dir: Optional[Path] = None) -> StaticShape:
        """``dlo shape``."""
    def evaluate(self, points: Optional[int] = None) -> StaticShape:
        """``dlo energy``."""
    def plan(
        self,
        progress: Optional[Progress] = None,
        log_dir: Optional[Path] = None,
        max_speed: Optional[float] = None,
        max_angular_speed: Optional[float] = None,
    ) -> Plan:
        """``dlo plan``: with ``log_dir``, the log and the trajectory CSV are written there."""
    def margin(self, progress: Optional[Progress] = None, log_dir: Optional[Path] = None) -> Margin:
        """``dlo margin``."""

def plan(
    problem: StaticProblem,
    start: End,
    goal: End,
    settings: Optional[Settings] = None,
    solver: Optional[Settings] = None,
    progress: Optional[Progress] = None,
    log_dir: Optional[Path] = None,
    name: str = "plan",
    max_speed: Optional[float] = None,
    max_angular_speed: Optional[float] = None,
) -> Plan:
    """Plans, verifies and replays the motion of the controlled end from ``start`` to
    ``goal`` of the rod held as ``problem`` says. ``settings`` takes a case file's ``plan``
    keys (other than start and goal), ``solver`` its ``solver`` keys. With ``log_dir``, writes
    ``<name>.mcap`` and ``<name>.trajectory.csv`` as ``dlo plan`` does; ``max_speed`` (length
    units/s) and ``max_angular_speed`` (rad/s) time the gripper trajectory."""

def grasp_margin(
    problem: StaticProblem,
    settings: Optional[Settings] = None,
    initial: Optional[Sequence[float]] = None,
    solver: Optional[Settings] = None,
    progress: Optional[Progress] = None,
    log_dir: Optional[Path] = None,
    name: str = "grasp",
) -> Margin:
    """The disturbance force margin (§6) of the grasp ``problem`` holds; ``settings`` takes a
    case file's ``grasp`` keys."""

def solve_repeatedly(problem: StaticProblem, repeats: int) -> list[float]:
    """Seconds of ``repeats`` solves timed in Rust (the benchmark's reference)."""
