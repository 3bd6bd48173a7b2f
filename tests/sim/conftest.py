"""Shared fixtures of the simulation tests: a box on the table at a known pose."""

from __future__ import annotations

import numpy as np
import pytest

from haptic.sim.scene import TABLE_TOP_Z, compose_scene, scene_object_from_parts

BOX_HALF = np.array([0.05, 0.04, 0.03])
BOX_CENTRE = np.array([0.56, 0.0, TABLE_TOP_Z + 0.03])


def box_parts(half=BOX_HALF) -> list[np.ndarray]:
    return [np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half]


def l_shape_parts() -> list[np.ndarray]:
    """A two-piece L: a 10x8x3 cm slab with a 4x8x5 cm block on one end."""
    a = box_parts(np.array([0.05, 0.04, 0.015]))[0] + [0.0, 0.0, 0.015]
    b = box_parts(np.array([0.02, 0.04, 0.025]))[0] + [0.03, 0.0, 0.055]
    return [a, b]


def box_pose(centre=BOX_CENTRE) -> np.ndarray:
    t = np.eye(4)
    t[:3, 3] = centre
    return t


@pytest.fixture(scope="module")
def box_scene():
    return compose_scene(scene_object_from_parts("testbox", box_parts()), box_pose())
