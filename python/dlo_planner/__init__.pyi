from ._dlo import (
    Case as Case,
    End as End,
    InputError as InputError,
    Obstacle as Obstacle,
    Rod as Rod,
    StaticProblem as StaticProblem,
    UnreachableError as UnreachableError,
    __version__ as __version__,
    grasp_margin as grasp_margin,
    plan as plan,
)
from .results import (
    Margin as Margin,
    Plan as Plan,
    Report as Report,
    Shapes as Shapes,
    StaticShape as StaticShape,
    Trajectory as Trajectory,
)
