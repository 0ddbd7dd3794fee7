"""Scene's setters: the eye, the camera poses, the obstacle and its display, validated."""

import math

import numpy as np
import pytest

import seethru
from conftest import REPO, SCENE


def test_bad_setter_values_are_refused_with_the_range():
    scene = seethru.Scene.load(SCENE)
    before = (scene.eye, scene.obstacle_pose.copy(), scene.display_size)
    with pytest.raises(ValueError, match=r"eye: the position must be finite, each coordinate in \[-1e"):
        scene.eye = (math.nan, 1.2, 0.0)
    with pytest.raises(ValueError, match=r"display_size: width 0 is out of range \[1e-6, 100\] metres"):
        scene.display_size = (0.0, 0.3)
    with pytest.raises(ValueError, match=r"display_size: height 200 is out of range"):
        scene.display_size = (0.3, 200.0)
    bad_row = scene.obstacle_pose.copy()
    bad_row[3, 0] = 1.0
    with pytest.raises(ValueError, match=r"obstacle_pose: the last row of a rigid transform must be \[0, 0, 0, 1\]"):
        scene.obstacle_pose = bad_row
    far = scene.driver_pose.copy()
    far[0, 3] = 1e12
    with pytest.raises(ValueError, match="driver_pose: the position must be finite"):
        scene.driver_pose = far
    mirrored = scene.back_pose.copy()
    mirrored[:3, 0] *= -1
    with pytest.raises(ValueError, match=r"back_pose: the upper-left 3×3 must be a rotation .*determinant \+1"):
        scene.back_pose = mirrored
    # A refused value changes nothing.
    assert (scene.eye, scene.display_size) == (before[0], before[2])
    assert np.array_equal(scene.obstacle_pose, before[1])


def test_moving_and_resizing_the_obstacle_changes_the_run():
    scene = seethru.Scene.load(SCENE)
    base = seethru.run(scene, width=64, spp=1).metrics["display_pixels"]
    moved = scene.copy()
    pose = moved.obstacle_pose
    pose[:3, 3] += 0.05 * pose[:3, 2]  # 5 cm towards the driver: the display looks larger
    moved.obstacle_pose = pose
    assert np.array_equal(moved.obstacle_pose, pose)
    assert seethru.run(moved, width=64, spp=1).metrics["display_pixels"] > base
    smaller = scene.copy()
    w, h = smaller.display_size
    smaller.display_size = (w / 2, h)
    assert smaller.display_size == (w / 2, h)
    assert seethru.run(smaller, width=64, spp=1).metrics["display_pixels"] < base
    # The copy's changes leave the original as it was.
    assert seethru.run(scene, width=64, spp=1).metrics["display_pixels"] == base


def test_a_maps_dropped_parts_are_the_scenes_warnings(tmp_path):
    # intersection.toml's map with a <geometry> of no length added, which the importer
    # drops and says so; the bundled map itself has no warning.
    bundled = REPO / "scenes" / "intersection.toml"
    assert seethru.Scene.load(bundled).warnings == []
    xodr = (REPO / "assets" / "roads" / "intersection.xodr").read_text()
    dropped = '<geometry s="0" x="0" y="0" hdg="0" length="0"><line/></geometry>'
    (tmp_path / "map.xodr").write_text(xodr.replace("</planView>", dropped + "</planView>", 1))
    text = bundled.read_text().replace('xodr = "../assets/roads/intersection.xodr"', 'xodr = "map.xodr"')
    (tmp_path / "scene.toml").write_text(text)
    warnings = seethru.Scene.load(tmp_path / "scene.toml").warnings
    assert len(warnings) == 1 and "map.xodr" in warnings[0] and "<geometry>" in warnings[0], warnings
