"""Reading an episode recording back (rerun's own reader): for tests and reports."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from haptic.errors import RecordingError

if TYPE_CHECKING:
    pass


@dataclass
class EntityData:
    """One entity of a recording read back."""

    path: str
    """Entity path, e.g. ``/plots/interpretations``."""
    static: dict[str, list]
    """Component column (``Archetype:field``) -> its static value (a list of instances)."""
    timelines: dict[str, list]
    """Timeline name -> one value per temporal row, in logging order (sequence: int; duration: seconds; None
    where the row has no value on that timeline)."""
    components: dict[str, list]
    """Component column -> one value per temporal row (a list of instances, or None where not logged)."""

    @property
    def rows(self) -> int:
        """Number of temporal rows."""
        return max((len(v) for v in self.timelines.values()), default=0)

    def series(self, component: str, timeline: str = "move") -> tuple[list, list]:
        """``(times, values)`` of the temporal rows that hold ``component``, in logging order."""
        values = self.components.get(component, [])
        times = self.timelines.get(timeline, [None] * len(values))
        keep = [i for i, v in enumerate(values) if v is not None]
        return [times[i] for i in keep], [values[i] for i in keep]


def load_recording(path: str | os.PathLike, *, blueprint: bool = False) -> dict[str, EntityData]:
    """Every entity of the (first) recording in an ``.rrd`` file, read with rerun's own
    :class:`rerun.chunk.RrdReader`; keys are entity paths without the leading slash. ``blueprint=True``
    reads the file's (last) blueprint instead: its views (``view/<id>``, with ``ViewBlueprint:*`` and their
    properties, such as ``view/<id>/EyeControls3D``), containers and panels, on the ``blueprint`` timeline."""
    import pyarrow as pa
    from rerun.chunk import RrdReader

    p = Path(path)
    if not p.is_file():
        raise RecordingError(f"{p}: no such recording")
    try:
        reader = RrdReader(p)
        if blueprint:
            stores = reader.blueprints()
            if not stores:
                raise RecordingError(f"{p}: the recording holds no blueprint")
            chunks = reader.stream(store=stores[-1]).to_chunks()
        else:
            chunks = reader.stream().to_chunks()
    except RecordingError:
        raise
    except Exception as exc:  # noqa: BLE001 -- rerun raises plain exceptions on a bad file
        raise RecordingError(f"{p}: not a readable rerun recording ({exc})") from exc
    temporal: dict[str, list[tuple[bytes, dict]]] = {}
    static: dict[str, dict[str, list]] = {}
    for ch in chunks:
        batch = ch.to_record_batch()
        row_ids: list[bytes] = [b""] * ch.num_rows
        cols: dict[tuple[str, str], list] = {}
        for fld, col in zip(batch.schema, batch.columns, strict=True):
            kind = (fld.metadata or {}).get(b"rerun:kind", b"").decode()
            if kind == "index" and pa.types.is_duration(fld.type):  # to seconds (as_py would drop nanoseconds)
                scale = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}[fld.type.unit]
                cols[("t", fld.name)] = [v * scale if v is not None else None for v in col.cast(pa.int64()).to_pylist()]
                continue
            if kind == "index" and pa.types.is_timestamp(fld.type):  # nanoseconds since the epoch, as int
                cols[("t", fld.name)] = col.cast(pa.int64()).to_pylist()
                continue
            values = col.to_pylist()
            if kind == "control":
                row_ids = [bytes(x) if x is not None else b"" for x in values]
            elif kind == "index":
                cols[("t", fld.name)] = values
            else:
                cols[("c", fld.name)] = values
        ep = ch.entity_path.lstrip("/")
        if ch.is_static:
            for (_, name), values in cols.items():
                if values and values[-1] is not None:
                    static.setdefault(ep, {})[name] = values[-1]
            continue
        for r in range(ch.num_rows):
            temporal.setdefault(ep, []).append((row_ids[r], {k: v[r] for k, v in cols.items()}))
    out: dict[str, EntityData] = {}
    for ep in sorted(set(temporal) | set(static)):
        rows = sorted(temporal.get(ep, []), key=lambda x: x[0])  # row ids (TUIDs) sort in logging order
        keys = sorted({k for _, d in rows for k in d})
        out[ep] = EntityData(
            path="/" + ep,
            static=static.get(ep, {}),
            timelines={k[1]: [d.get(k) for _, d in rows] for k in keys if k[0] == "t"},
            components={k[1]: [d.get(k) for _, d in rows] for k in keys if k[0] == "c"},
        )
    return out


