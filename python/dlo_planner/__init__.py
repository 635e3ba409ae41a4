"""dlo-planner: static shapes, minimum-energy deformation plans and grasp margins of
deformable linear objects (cables, wires, threads, thin strips), after Wakamatsu & Hirai,
*Static Modeling of Linear Object Deformation Based on Differential Geometry* (IJRR 2004).

Build a problem in code::

    import dlo_planner as dlo
    rod = dlo.Rod(length=1.0, flexural_rigidity=1.0)
    problem = dlo.StaticProblem(rod).clamp(0.0, [0, 0, 0], [0.0])
    shape = problem.solve()
    shape.energy.total, shape.positions[-1]

or run a case file as the `dlo` command does::

    case = dlo.Case.load("planning_cases/plan_paper_planar.json")
    plan = case.plan(log_dir="logs")
    plan.verdict, plan.gripper.positions

Every solve releases the GIL, so threads and process pools run in parallel. Results are the
classes of :mod:`dlo_planner.results`: the CLI's JSON report as attributes (``to_dict()``
gives the dict itself) plus NumPy arrays. Bad input raises :class:`InputError` (a
``ValueError``) whose ``field`` and ``message`` say what is wrong; a plan's start or goal that
no static shape reaches raises its subclass :class:`UnreachableError`.
"""

from ._dlo import (
    Case,
    End,
    InputError,
    Obstacle,
    Rod,
    StaticProblem,
    UnreachableError,
    __version__,
    grasp_margin,
    plan,
)
from .results import Margin, Plan, Report, Shapes, StaticShape, Trajectory

__all__ = [
    "Case",
    "End",
    "InputError",
    "Margin",
    "Obstacle",
    "Plan",
    "Report",
    "Rod",
    "Shapes",
    "StaticProblem",
    "StaticShape",
    "Trajectory",
    "UnreachableError",
    "__version__",
    "grasp_margin",
    "plan",
]
