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
