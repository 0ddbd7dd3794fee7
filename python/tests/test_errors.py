"""Bad input raises ValueError or OSError with the command line's one-line message."""

import pytest

import seethru
from conftest import MINIMAL, SCENE, seethru_cli


def test_missing_scene_is_an_os_error(tmp_path):
    path = tmp_path / "absent.toml"
    with pytest.raises(OSError) as raised:
        seethru.Scene.load(path)
    cli = seethru_cli("render", str(path), "--out", str(tmp_path / "out"))
    assert cli.returncode != 0
    assert cli.stderr.strip() == f"error: {raised.value}"


def test_bad_scene_key_is_a_value_error_with_the_cli_message(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(MINIMAL.replace("width = 0.3", "widht = 0.3"))
    seethru.Scene.load(tmp_path.joinpath("good.toml")) if tmp_path.joinpath("good.toml").write_text(MINIMAL) else None
    with pytest.raises(ValueError) as raised:
        seethru.Scene.load(path)
    cli = seethru_cli("render", str(path), "--out", str(tmp_path / "out"))
    assert cli.stderr.strip() == f"error: {raised.value}"
    assert "widht" in str(raised.value) and "bad.toml" in str(raised.value)


def test_render_arguments_are_checked():
    scene = seethru.Scene.load(SCENE)
    with pytest.raises(ValueError, match=r"spp=0 is out of range: must be an integer in \[1, 4096\]"):
        scene.render("truth", width=32, spp=0)
    with pytest.raises(ValueError, match=r"width=0 is out of range"):
        scene.render("truth", width=0)
    with pytest.raises(ValueError, match=r'view "sideways" is not one of truth, occluded, frontal, back'):
        scene.render("sideways")


def test_run_options_are_checked():
    scene = seethru.Scene.load(SCENE)
    with pytest.raises(ValueError, match=r'method="flat" is not one of none, planar'):
        seethru.run(scene, method="flat")
    with pytest.raises(ValueError, match=r"unknown option \"colour\""):
        seethru.run(scene, colour=1)
    with pytest.raises(ValueError, match=r"band=0 is out of range: must be an integer in \[1, 1000\]"):
        seethru.run(scene, band=0)
    with pytest.raises(ValueError, match=r"fill is read only by method depth \(its disocclusion holes\)"):
        seethru.run(scene, fill="inpaint")


def test_an_eye_behind_the_display_is_refused_as_by_the_cli(tmp_path):
    scene = seethru.Scene.load(SCENE)
    x, y, z = scene.obstacle_pose[:3, 3]
    normal = scene.obstacle_pose[:3, 2]
    scene.eye = tuple(float(v) for v in (scene.obstacle_pose[:3, 3] - 0.5 * normal))
    with pytest.raises(ValueError) as raised:
        seethru.run(scene, width=32, spp=1)
    assert str(raised.value)  # the library's message, one line
    assert "\n" not in str(raised.value)
