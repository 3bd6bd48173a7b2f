"""scripts/bench_learn.py chooses its objects: ``--variants`` keeps the perturbations of the kinds named."""

import sys
from pathlib import Path

from haptic.geometry import load_library

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))

from bench_learn import objects  # noqa: E402


def test_variants_keep_the_kinds_named(tmp_path):
    lib = {k: v for k, v in load_library().items() if k in ("WEDGE01", "TETRA01L")}
    every = objects(lib, 0, 0, tmp_path / "all")
    dims = objects(lib, 0, 0, tmp_path / "dim", ("dim",))
    tags = [Path(it["path"]).stem.rsplit("__", 1)[1] for it in dims]
    assert tags and all(t.startswith("dim") for t in tags)
    assert {it["family"] for it in dims} == {"dimension"}
    # the same objects as in the whole set (the perturbations are drawn before they are kept)
    assert {Path(it["path"]).name for it in dims} <= {Path(it["path"]).name for it in every}
    both = objects(lib, 0, 0, tmp_path / "v", ("v", "ch"))
    assert {it["family"].split(",")[0] for it in both} == {"vertex", "chamfer"}
