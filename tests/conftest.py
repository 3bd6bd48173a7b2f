import os

os.environ.setdefault("MUJOCO_GL", "disable")


import pytest  # noqa: E402


@pytest.fixture(scope="session")
def corpus(tmp_path_factory):
    """The corpus of third-party-like model files, written once per test session: (manifest, dirs)."""
    import json

    from haptic.geometry.corpus import write_corpus

    root = tmp_path_factory.mktemp("corpus")
    dirs = write_corpus(root, seed=0)
    return json.loads((root / "manifest.json").read_text()), dirs


@pytest.fixture(scope="session")
def small_library(tmp_path_factory):
    """Three seed models in a library of their own (a smaller tree keeps the environment's checks quick)."""
    import shutil

    from haptic.geometry.io import DEFAULT_LIBRARY

    d = tmp_path_factory.mktemp("lib")
    for name in ("BOX01", "WEDGE01", "TETRA01L"):
        src = next(DEFAULT_LIBRARY.glob(f"{name}.*"))
        shutil.copy(src, d / src.name)
    return str(d)
