"""The contact trace: what a fingertip sensed, one row per control tick (the segmenter's input, kept with a
move's result for perception and recordings).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PHASES = ("free", "approach", "settle", "face", "roll", "stroke", "ridge", "vertex", "circle")
"""Phase labels of the trace samples (``ContactTrace.phase`` holds indices into this tuple)."""


@dataclass(frozen=True, eq=False)
class ContactTrace:
    """What the fingertip recorded, one row per control tick (world frame)."""

    time: np.ndarray
    """Simulation time (n,) [s]."""
    tip_in_world: np.ndarray
    """Pad centre (n, 3) [m] (forward kinematics of the encoders)."""
    hand_rotation: np.ndarray
    """Hand rotation ``world_from_hand`` (n, 3, 3)."""
    point_in_world: np.ndarray
    """Sensed contact point (n, 3) [m]; NaN without contact."""
    normal_in_world: np.ndarray
    """Sensed unit normal (n, 3), out of the touched surface; NaN without contact."""
    force: np.ndarray
    """Sensed normal force (n,) [N]."""
    phase: np.ndarray
    """Phase index (n,) into :data:`PHASES`."""

    def __len__(self) -> int:
        return len(self.time)

    @property
    def in_contact(self) -> np.ndarray:
        """Rows with a valid contact (n,) bool."""
        return np.isfinite(self.normal_in_world[:, 0])

    def select(self, mask: np.ndarray) -> ContactTrace:
        """The rows where ``mask`` holds."""
        return ContactTrace(*(a[mask] for a in self.columns()))

    def tail(self, k: int) -> ContactTrace:
        """The last ``k`` rows."""
        return ContactTrace(*(a[max(len(self) - k, 0) :] for a in self.columns()))

    def columns(self) -> tuple[np.ndarray, ...]:
        """The trace's arrays in the order of the constructor's arguments."""
        return (self.time, self.tip_in_world, self.hand_rotation, self.point_in_world, self.normal_in_world,
                self.force, self.phase)  # fmt: skip

    @staticmethod
    def concatenate(traces: list[ContactTrace]) -> ContactTrace:
        traces = [t for t in traces if len(t)]
        if not traces:
            return empty_trace()
        return ContactTrace(*(np.concatenate(cols) for cols in zip(*(t.columns() for t in traces), strict=True)))


def empty_trace() -> ContactTrace:
    return ContactTrace(np.zeros(0), np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros((0, 3)), np.zeros((0, 3)),
                        np.zeros(0), np.zeros(0, dtype=int))  # fmt: skip
