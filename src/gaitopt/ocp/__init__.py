"""gaitopt.ocp: generic multi-phase optimal control by direct collocation.

State a :class:`Problem` of :class:`Phase` objects, then ``tr = transcribe(problem, ...)`` and
``result = tr.solve(guess)``. See docs/ocp.md. Knows nothing of bipeds.
"""

from gaitopt.ocp.bounds import Bounds
from gaitopt.ocp.costate import costates, one_sided_costates
from gaitopt.ocp.guess import Guess, PhaseGuess, WarmStart, secant_start, warm_start_of
from gaitopt.ocp.layout import ConstraintLayout, Layout, PhaseLayout
from gaitopt.ocp.problem import (
    BoundaryConstraint,
    ControlLinkage,
    Duration,
    KnotStates,
    Linkage,
    Parameter,
    PathConstraint,
    Phase,
    PhaseEnds,
    Problem,
    named,
)
from gaitopt.ocp.refine import Refinement, refine, refined_mesh
from gaitopt.ocp.result import NlpSize, PhaseTrajectory, Result
from gaitopt.ocp.transcription import Transcription, transcribe
from gaitopt.ocp.validate import ProblemError

__all__ = [
    "BoundaryConstraint",
    "Bounds",
    "ConstraintLayout",
    "ControlLinkage",
    "Duration",
    "Guess",
    "KnotStates",
    "Layout",
    "Linkage",
    "NlpSize",
    "Parameter",
    "PathConstraint",
    "Phase",
    "PhaseEnds",
    "PhaseGuess",
    "PhaseLayout",
    "Problem",
    "ProblemError",
    "PhaseTrajectory",
    "Refinement",
    "Result",
    "Transcription",
    "WarmStart",
    "costates",
    "named",
    "one_sided_costates",
    "refine",
    "refined_mesh",
    "secant_start",
    "transcribe",
    "warm_start_of",
]
