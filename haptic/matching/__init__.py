"""Matching data components against models (seed §2.3–2.6)."""

from haptic.matching.components import DataComponent, DataEdge, DataFace, DataVertex, SensorNoise
from haptic.matching.library import LibraryArrays
from haptic.matching.pose import estimate_pose, pose_error, pose_from_edge_pair
from haptic.matching.recognition import PoseClass, PoseTolerance, Recognition, recognize
from haptic.matching.tree import Interpretation, InterpretationTree

__all__ = [
    "DataComponent",
    "DataEdge",
    "DataFace",
    "DataVertex",
    "Interpretation",
    "InterpretationTree",
    "LibraryArrays",
    "PoseClass",
    "PoseTolerance",
    "Recognition",
    "SensorNoise",
    "estimate_pose",
    "pose_error",
    "pose_from_edge_pair",
    "recognize",
]
