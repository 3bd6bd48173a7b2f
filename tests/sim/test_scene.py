"""Scene composition, seeded placement and export."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from conftest import box_parts, l_shape_parts

from haptic.errors import SceneError
from haptic.sim import scene as sc
from haptic.sim.scene import (
    OBJECT_REGION,
    TABLE_TOP_Z,
    compose_scene,
    export_scene,
    load_object,
    random_object_pose,
    scene_object_from_parts,
)


def _world_vertices(obj, t):
    return obj.vertices @ t[:3, :3].T + t[:3, 3]


@pytest.mark.parametrize("parts", [box_parts(), l_shape_parts()], ids=["box", "L"])
def test_random_pose_is_seeded_resting_and_within_reach(parts):
    obj = scene_object_from_parts("thing", parts)
    a = random_object_pose(obj, np.random.default_rng(7))
    b = random_object_pose(obj, np.random.default_rng(7))
    c = random_object_pose(obj, np.random.default_rng(8))
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)
    for seed in range(20):
        t = random_object_pose(obj, np.random.default_rng(seed))
        v = _world_vertices(obj, t)
        assert v[:, 2].min() == pytest.approx(TABLE_TOP_Z, abs=1e-9)
        centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
        (x0, x1), (y0, y1) = OBJECT_REGION
        assert x0 - 1e-9 <= centre[0] <= x1 + 1e-9 and y0 - 1e-9 <= centre[1] <= y1 + 1e-9


def test_object_meshes_sit_where_the_pose_puts_them():
    obj = scene_object_from_parts("L", l_shape_parts())
    scene = compose_scene(obj, seed=3)
    m = scene.compile()
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    for i, part in enumerate(obj.parts):
        g = m.geom(f"object_part{i}")
        adr, n = m.mesh_vertadr[g.dataid[0]], m.mesh_vertnum[g.dataid[0]]
        got = m.mesh_vert[adr : adr + n] @ d.geom_xmat[g.id].reshape(3, 3).T + d.geom_xpos[g.id]
        want = part @ scene.world_from_object[:3, :3].T + scene.world_from_object[:3, 3]
        np.testing.assert_allclose(np.sort(got, axis=0), np.sort(want, axis=0), atol=1e-6)


def test_library_object_loads_with_convex_pieces():
    obj = load_object("LBLOCK01")
    assert obj.name == "LBLOCK01" and len(obj.parts) >= 2  # non-convex: several convex mesh geoms
    assert len(load_object("BOX01").parts) == 1


def test_unknown_object_names_the_valid_ones():
    with pytest.raises(SceneError, match="valid names: .*BOX01"):
        load_object("NO_SUCH_MODEL")


def test_degenerate_part_is_refused():
    flat = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float) * 0.05
    with pytest.raises(SceneError, match="part 0"):
        scene_object_from_parts("flat", [flat])


def test_bad_pose_is_refused():
    t = np.eye(4)
    t[:3, :3] *= 2.0
    with pytest.raises(SceneError, match="rotation"):
        compose_scene(scene_object_from_parts("box", box_parts()), t)


def test_export_loads_in_plain_mujoco(tmp_path):
    scene = compose_scene(load_object("LBLOCK01"), seed=5)
    path = export_scene(scene, tmp_path / "out" / "scene.xml")
    m = mujoco.MjModel.from_xml_path(str(path))
    names = [m.joint(i).name for i in range(m.njnt)]
    assert sum(n.startswith("arm/") and "/hand/" not in n for n in names) == 6
    assert sum("/hand/" in n for n in names) == 16
    assert sum(m.sensor_type[i] == mujoco.mjtSensor.mjSENS_TOUCH for i in range(m.nsensor)) == 4
    assert sorted(p.suffix for p in path.parent.iterdir()) == [".stl", ".stl", ".xml"]
    assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home") >= 0


def test_failed_export_leaves_nothing_behind(tmp_path, monkeypatch):
    scene = compose_scene(scene_object_from_parts("box", box_parts()), seed=0)

    def boom(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(sc.mjcf, "export_with_assets", boom)
    with pytest.raises(SceneError, match="disk full"):
        export_scene(scene, tmp_path / "scene.xml")
    assert list(tmp_path.iterdir()) == []


def test_export_path_must_be_xml(tmp_path):
    scene = compose_scene(None)
    with pytest.raises(SceneError, match=r"\.xml"):
        export_scene(scene, tmp_path / "scene")


def test_checked_in_scene_matches_the_composition():
    m = mujoco.MjModel.from_xml_path(str(sc.REPO_ROOT / "scenes" / "scene.xml"))
    fresh = compose_scene(None).compile()
    for attr in ("njnt", "nbody", "ngeom", "nsite", "nsensor", "nu", "nkey"):
        assert getattr(m, attr) == getattr(fresh, attr), attr
    np.testing.assert_allclose(m.body_pos, fresh.body_pos, atol=1e-9)
    # the physics options too: a scene loaded from the export steps as the episodes' scenes do
    for attr in ("timestep", "impratio", "integrator", "cone", "disableflags", "enableflags"):
        assert getattr(m.opt, attr) == getattr(fresh.opt, attr), attr


def test_a_non_convex_model_is_decomposed_once_per_process(monkeypatch):
    """The second scene of the same library model reuses its convex pieces: the same parts, no second
    decomposition."""
    from haptic.geometry import load_library

    model = load_library()["LBLOCK01"]
    first = sc.scene_object_from_polyhedron(model)
    calls = []
    monkeypatch.setattr(sc, "convex_decomposition", lambda poly: calls.append(poly) or [])
    second = sc.scene_object_from_polyhedron(model)
    assert not calls and len(first.parts) == len(second.parts) > 1
    assert all(np.array_equal(a, b) for a, b in zip(first.parts, second.parts, strict=True))


def _differences(a: mujoco.MjModel, b: mujoco.MjModel) -> list[str]:
    """The model arrays and options in which ``a`` and ``b`` differ (the mesh files' names aside)."""
    out = []
    for name in dir(a):
        if name.startswith("_") or name in ("mesh_pathadr", "paths"):
            continue
        x = getattr(a, name)
        if isinstance(x, np.ndarray):
            y = getattr(b, name)
            if x.shape != y.shape or not np.array_equal(x, y, equal_nan=True):
                out.append(name)
    for name in dir(a.opt):
        x = getattr(a.opt, name)
        if not name.startswith("_") and not callable(x) and not np.array_equal(x, getattr(b.opt, name)):
            out.append(f"opt.{name}")
    return out


@pytest.mark.parametrize("name", [None, "BOX01", "LBLOCK01"])
def test_compiled_scene_is_the_composed_mjcf_model(name):
    """The model compiled from the spec parsed once per process is the one the composed MJCF compiles to: every
    array (bodies, geoms, meshes and their hulls, options, keyframe) equal, bit for bit, whatever scene was compiled
    before."""
    obj = load_object(name) if name else None
    scene = compose_scene(obj, seed=4)
    assert _differences(scene.compile(), compose_scene(load_object("FRAME01"), seed=1).compile())  # another scene
    mjcf_model = mujoco.MjModel.from_xml_string(scene.to_xml_string(), assets=scene.mjcf_model.get_assets())
    compiled = scene.compile()
    assert _differences(compiled, mjcf_model) == []
    assert compiled.names == mjcf_model.names and compiled.ngeom == mjcf_model.ngeom


def test_preloaded_scenes_need_no_decomposition(monkeypatch):
    """After :func:`preload_scenes` (what a process does before forking its workers) the scenes of its models need
    neither a decomposition nor a parse of the scene."""
    from haptic.geometry import load_library

    model = load_library()["FRAME01"]
    monkeypatch.setattr(sc, "_PIECES", type(sc._PIECES)())
    sc._robot_spec.cache_clear()
    sc.preload_scenes([model])
    calls = []
    monkeypatch.setattr(sc, "convex_decomposition", lambda poly: calls.append(poly) or [])
    monkeypatch.setattr(sc.mujoco.MjSpec, "from_string", lambda *a, **k: calls.append(a) or None)
    scene = compose_scene(sc.scene_object_from_polyhedron(model), seed=1)
    assert scene.compile().ngeom > 50 and not calls


def test_preload_splits_the_non_convex_models_in_another_process(monkeypatch):
    """:func:`~haptic.episode.worlds.preload_physics` splits the non-convex models in a process it forks while it
    imports and parses the scene, and the scenes keep the pieces that process returns: the same arrays as this
    process's own decomposition."""
    import os

    from haptic.episode import worlds
    from haptic.geometry import load_library

    model = load_library()["FRAME01"]
    monkeypatch.setattr(sc, "_PIECES", type(sc._PIECES)())
    worlds.preload_physics([model], jobs=2)
    own = sc.convex_decomposition(model)
    assert len(sc._PIECES[model]) == len(own)
    assert all(a.dtype == b.dtype and a.tobytes() == b.tobytes() for a, b in zip(sc._PIECES[model], own, strict=True))
    monkeypatch.setattr(sc, "_PIECES", type(sc._PIECES)())
    tetrahedron = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.01]])
    monkeypatch.setattr(worlds, "convex_decomposition", lambda poly: [tetrahedron + os.getpid()])  # who split it
    worlds.preload_physics([model])
    ((pid, *_), *_), *_ = sc._PIECES[model]
    assert pid != os.getpid()


def test_a_model_at_another_size_compiles_with_its_own_meshes():
    """MuJoCo keeps the meshes it has read by file name for the process's next compilations: the same model at
    another size, its convex pieces as many and their files as long, still compiles with its own meshes."""
    from haptic.geometry import load_library
    from haptic.geometry.perturb import scaled_to

    model = load_library()["FRAME01"]
    compose_scene(sc.scene_object_from_polyhedron(model), seed=1).compile()
    small = compose_scene(sc.scene_object_from_polyhedron(scaled_to(model, 0.03, "FRAME01")), seed=1)
    mjcf_model = mujoco.MjModel.from_xml_string(small.to_xml_string(), assets=small.mjcf_model.get_assets())
    assert _differences(small.compile(), mjcf_model) == []
