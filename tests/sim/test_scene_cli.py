"""``haptic scene`` subcommand."""

from __future__ import annotations

import argparse

import mujoco

from haptic.sim import cli


def _run(argv):
    ap = argparse.ArgumentParser()
    cli.add_parser(ap.add_subparsers(dest="command"))
    args = ap.parse_args(argv)
    return cli.run(args)


def test_scene_export(tmp_path, capsys):
    out = tmp_path / "s" / "scene.xml"
    assert _run(["scene", "--object", "WEDGE01", "--seed", "2", "--export", str(out)]) == 0
    m = mujoco.MjModel.from_xml_path(str(out))
    assert m.njnt == 22 and m.nu == 22
    assert "wrote" in capsys.readouterr().out


def test_scene_unknown_object_is_one_line_on_stderr(tmp_path, capsys):
    from haptic.cli import main

    assert main(["scene", "--object", "NOPE", "--export", str(tmp_path / "scene.xml")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "valid names" in err and err.startswith("haptic: error: ")
    assert not (tmp_path / "scene.xml").exists()
