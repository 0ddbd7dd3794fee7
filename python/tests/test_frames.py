"""Renders and runs from Python against the command line's EXRs and metrics.json, bit for bit."""

import json
import math

import numpy as np
import OpenEXR
import pytest

import seethru
from conftest import MINIMAL, SCENE, SPP, WIDTH, seethru_cli


def exr_channels(path):
    """Every channel of an EXR the CLI wrote, read by OpenEXR (not by seethru)."""
    with OpenEXR.File(str(path), separate_channels=True) as f:
        return {name: np.array(c.pixels) for name, c in f.channels().items()}


def same_bits(a, b):
    """Bit-for-bit equality (NaN equal to itself, -0.0 unequal to 0.0)."""
    a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def assert_frame_is_exr(frame, path):
    ch = exr_channels(path)
    h, w = ch["Z"].shape
    assert (frame.height, frame.width) == (h, w)
    expected = {
        "colour": np.stack([ch["R"], ch["G"], ch["B"]], axis=-1),
        "depth": ch["Z"],
        "camera_z": ch["camera_z.Z"],
        "position": np.stack([ch["P.X"], ch["P.Y"], ch["P.Z"]], axis=-1),
        "normal": np.stack([ch["N.X"], ch["N.Y"], ch["N.Z"]], axis=-1),
        "object_id": ch["id.object"],
        "part_id": ch["id.part"],
    }
    for name, want in expected.items():
        got = getattr(frame, name)
        assert same_bits(got, want), f"{frame.view}.{name} differs from {path}"


@pytest.mark.parametrize("view", ["truth", "occluded", "frontal", "back"])
def test_render_matches_cli_exr(cli_render, view):
    scene = seethru.Scene.load(SCENE)
    frame = scene.render(view, width=WIDTH, spp=SPP)
    assert frame.view == view
    assert frame.colour.shape == (frame.height, frame.width, 3)
    assert frame.colour.dtype == np.float32 and frame.object_id.dtype == np.uint32
    # A frame that shows something: not all sky, not one object.
    assert len(np.unique(frame.object_id)) > 2
    assert_frame_is_exr(frame, cli_render / f"{view}.exr")


def test_run_matches_cli(cli_run):
    scene = seethru.Scene.load(SCENE)
    result = seethru.run(scene, width=WIDTH, spp=SPP, method="planar", d2="auto")
    for view in ["truth", "occluded", "frontal", "back", "display", "seethru"]:
        assert_frame_is_exr(result.frames[view], cli_run / f"{view}.exr")
    metrics = json.loads((cli_run / "metrics.json").read_text())
    assert result.metrics == metrics
    # run.json, but for what is measured rather than computed: time and memory.
    measured = {"timings_s", "peak_rss_bytes"}
    report = json.loads((cli_run / "run.json").read_text())
    assert set(result.report) == set(report)
    assert {k: v for k, v in result.report.items() if k not in measured} == {
        k: v for k, v in report.items() if k not in measured
    }
    mis = exr_channels(cli_run / "misregistration.exr")
    assert same_bits(result.misregistration, mis["Y"])
    assert same_bits(result.missing.astype(np.float32), mis["missing.mask"])
    # The mean misregistration in metrics.json is the mean of the map's finite pixels.
    finite = result.misregistration[np.isfinite(result.misregistration)]
    assert finite.size > 0


def test_read_frame_reads_the_cli_exr(cli_render):
    frame = seethru.read_frame(cli_render / "truth.exr")
    assert_frame_is_exr(frame, cli_render / "truth.exr")


def test_moving_the_eye_moves_the_render():
    scene = seethru.Scene.load(SCENE)
    before = scene.render("truth", width=64, spp=1)
    x, y, z = scene.eye
    scene.eye = (x + 0.1, y, z)
    assert scene.eye == (x + 0.1, y, z)
    assert np.allclose(scene.driver_pose[:3, 3], (x + 0.1, y, z))
    after = scene.render("truth", width=64, spp=1)
    # Every visible point is seen from 10 cm to the right: the pixel-centre distance changes.
    assert not np.array_equal(before.depth, after.depth)
    # The camera centre is the eye: |P - eye| is the depth along the ray.
    hit = np.isfinite(after.depth)
    dist = np.linalg.norm(after.position[hit] - np.array(scene.eye, dtype=np.float32), axis=-1)
    assert np.allclose(dist, after.depth[hit], rtol=1e-4)


def test_poses_round_trip_and_refuse_non_rigid():
    scene = seethru.Scene.load(SCENE)
    pose = scene.frontal_pose
    assert pose.shape == (4, 4) and pose.dtype == np.float64
    assert np.allclose(pose[:3, :3].T @ pose[:3, :3], np.eye(3))
    scene.frontal_pose = pose
    assert np.array_equal(scene.frontal_pose, pose)
    scaled = pose.copy()
    scaled[:3, :3] *= 2
    with pytest.raises(ValueError, match="frontal_pose: the upper-left 3×3 must be a rotation"):
        scene.frontal_pose = scaled


def test_buffers_are_handed_over_without_a_copy():
    scene = seethru.Scene.load(SCENE)
    frame = scene.render("truth", width=1280, height=720, spp=1)
    assert frame.colour.shape == (720, 1280, 3)
    for name, address in frame._buffer_addresses.items():
        array = getattr(frame, name)
        # numpy's data pointer is where Rust rendered the frame: no copy was made.
        assert array.ctypes.data == address, name
        assert array.flags.c_contiguous
    assert len(frame._buffer_addresses) == 7


def test_a_photometric_scenes_colour_times_its_white_is_the_exrs_cd_m2(tmp_path):
    light = (
        "[sun]\nilluminance_lux = 40000\nelevation_deg = 50\nazimuth_deg = 200\n"
        "[sky]\nzenith_luminance_cd_m2 = 3000\n[photometry]\nwhite_cd_m2 = 800\n"
    )
    path = tmp_path / "lit.toml"
    path.write_text(light + MINIMAL)
    frame = seethru.Scene.load(path).render("truth", spp=1)
    assert frame.white_cd_m2 == 800.0
    out = tmp_path / "out"
    done = seethru_cli("render", str(path), "--view", "truth", "--exr", "colour", "--spp", "1", "--out", str(out))
    assert done.returncode == 0, done.stderr
    ch = exr_channels(out / "truth.exr")
    exr = np.stack([ch["R"], ch["G"], ch["B"]], axis=-1)
    assert np.array_equal(frame.colour * np.float32(800.0), exr)
    assert seethru.Scene.load(SCENE).render("truth", width=16, spp=1).white_cd_m2 is None
