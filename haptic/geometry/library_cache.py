"""A per-process cache of loaded model libraries, so that the episodes of a sweep that run in one worker load
(and validate) a library's files once, not once per episode.

The key is the library directory with the name, size and modification time of every model file in it: a library
edited on disk is loaded again.
"""

from __future__ import annotations

import os
from collections import OrderedDict

from haptic.geometry.io import default_units, library_stamp, load_library
from haptic.geometry.polyhedron import Polyhedron

CACHE_SIZE = 4
"""Libraries one process keeps (least recently used dropped first)."""
_CACHE: OrderedDict[tuple, dict[str, Polyhedron]] = OrderedDict()


def cached_library(
    directory: str | os.PathLike | None = None, skip_invalid: bool = False, units: str | None = None
) -> dict[str, Polyhedron]:
    """:func:`~haptic.geometry.io.load_library`, from this process's cache when the files (and the units they
    are read in) are unchanged.

    Returns a new dict each time (of the same, immutable, models)."""
    key = (skip_invalid, default_units(directory, units), *library_stamp(directory))
    lib = _CACHE.get(key)
    if lib is None:
        lib = load_library(directory, skip_invalid=skip_invalid, units=units)
        _CACHE[key] = lib
        while len(_CACHE) > CACHE_SIZE:
            _CACHE.popitem(last=False)
    else:
        _CACHE.move_to_end(key)
    return dict(lib)
