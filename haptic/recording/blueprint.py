"""The default layout of an episode recording in the rerun viewer."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import rerun.blueprint as rrb

if TYPE_CHECKING:
    pass


@dataclass(frozen=True)
class Framing:
    """Where the default blueprint's 3-D views start looking (world frame)."""

    object_eye: tuple[float, float, float] | None = None
    """Eye of the ``object`` view [m] (None: the viewer's own framing of everything)."""
    object_target: tuple[float, float, float] | None = None
    """Point the ``object`` view looks at and orbits: the object's centre [m]."""
    fingertip_eye: tuple[float, float, float] | None = None
    """Eye of the ``fingertip`` view relative to the pad [m] (the view's origin is ``world/hand/pad``, which
    moves with the pad, so the eye follows it)."""
    timeline: str = "move"
    """Timeline the recording opens on (``sim_time`` when there are physics traces)."""


def default_blueprint(framing: Framing | None = None) -> rrb.Blueprint:
    """The layout a recording opens with: on the left the ``object`` 3-D view (its eye on the object's region)
    over the ``fingertip`` view (following the active pad close up) and the latest decision's candidate table (in a
    tab beside it, its candidate placements of several fingertips);
    on the right the interpretations and pose classes (log10, with a marker per move coloured by its kind and
    failed moves crossed), the normal force, the path cost and the logs."""
    f = framing or Framing()
    up = (0.0, 0.0, 1.0)
    obj_eye = (
        rrb.EyeControls3D(position=f.object_eye, look_target=f.object_target, eye_up=up)
        if f.object_eye is not None else None
    )  # fmt: skip
    tip_eye = (
        rrb.EyeControls3D(position=f.fingertip_eye, look_target=(0.0, 0.0, 0.0), eye_up=up)
        if f.fingertip_eye is not None else None
    )  # fmt: skip
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(
                rrb.Spatial3DView(origin="world", name="object", eye_controls=obj_eye,
                                  background=rrb.BackgroundKind.GradientBright),
                rrb.Horizontal(
                    rrb.Spatial3DView(origin="world/hand/pad", contents="/world/**", name="fingertip",
                                      eye_controls=tip_eye, background=rrb.BackgroundKind.GradientBright),
                    # one text document per view (a view given two shows an error instead): the decision's
                    # candidate moves, and beside them in a tab the candidate placements of several fingertips
                    rrb.Tabs(
                        rrb.TextDocumentView(origin="decision/scores", name="candidate moves"),
                        rrb.TextDocumentView(origin="decision/placements", name="candidate placements"),
                        active_tab=0,
                    ),
                    column_shares=[1, 1],
                ),
                row_shares=[3, 2],
            ),
            rrb.Vertical(
                rrb.TimeSeriesView(
                    origin="plots", name="interpretations, pose classes (log10)",
                    contents=["plots/interpretations", "plots/pose_classes", "plots/moves/**"],
                    plot_legend=rrb.PlotLegend(corner=rrb.Corner2D.RightTop),
                ),  # fmt: skip
                rrb.TimeSeriesView(origin="plots", contents=["plots/force"], name="normal force [N]"),
                rrb.TimeSeriesView(origin="plots", contents=["plots/path_cost"], name="path cost [units]"),
                rrb.TextLogView(origin="log", name="log"),
                row_shares=[3, 2, 2, 2],
            ),
            column_shares=[3, 2],
        ),
        rrb.TimePanel(timeline=f.timeline, state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.BlueprintPanel(state="collapsed"),
    )
