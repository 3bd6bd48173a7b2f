"""The per-process library cache: loaded once while the files are unchanged, again when they change."""

import shutil

from haptic.geometry import DEFAULT_LIBRARY
from haptic.geometry.library_cache import cached_library


def test_cached_until_a_file_changes(tmp_path):
    d = tmp_path / "lib"
    shutil.copytree(DEFAULT_LIBRARY, d)
    a, b = cached_library(d), cached_library(d)
    assert a is not b and a.keys() == b.keys() and all(a[k] is b[k] for k in a)
    (d / "BOX01.json").unlink()
    c = cached_library(d)
    assert "BOX01" not in c and c["WEDGE01"] is not a["WEDGE01"]
