"""Cameras in time from Python (docs/guide/time.md): a scene's shutter keys give each
frame's per-row exposure times, and a single run sees the vehicle's motion through them."""

import numpy as np
import pytest

import seethru
from conftest import REPO

ROLLING = 'shutter = "rolling"\nreadout_ms = 30.0\nexposure_ms = 8.0'


def das_with(tmp_path, frontal_keys: str) -> seethru.Scene:
    text = (REPO / "scenes" / "das.toml").read_text()
    text = text.replace("[camera.frontal]", "[camera.frontal]\n" + frontal_keys)
    text = text.replace("../assets", str(REPO / "assets"))
    path = tmp_path / "das_in_time.toml"
    path.write_text(text)
    return seethru.Scene.load(path)


def test_row_times_are_the_readout_and_exposure_of_each_row(tmp_path):
    scene = das_with(tmp_path, ROLLING)
    frame = scene.render("frontal", width=64, spp=1)
    times = frame.row_times
    assert times.shape == (frame.height, 2) and times.dtype == np.float64
    # The last row read at the frame's instant, the first 30 ms before; each exposed 8 ms
    # before its readout, rows evenly spread.
    h = frame.height
    ends = -0.03 * (h - 1 - np.arange(h)) / (h - 1)
    np.testing.assert_allclose(times[:, 1], ends, rtol=0, atol=1e-15)
    np.testing.assert_allclose(times[:, 0], ends - 0.008, rtol=0, atol=1e-15)
    # A global shutter with an instant exposure: every row at the frame's instant.
    still = seethru.Scene.load(REPO / "scenes" / "das.toml")
    assert not still.render("frontal", width=64, spp=1).row_times.any()


def test_a_run_sees_the_vehicle_turn_through_the_frontal_shutter(tmp_path):
    scene = das_with(tmp_path, ROLLING)
    small = dict(width=64, frontal_width=128, back_width=160, spp=1, outside="black")
    still = seethru.run(scene, **small)
    turning = seethru.run(scene, yaw_rate=20.0, **small)
    frames = turning.frames
    assert frames["frontal"].row_times[0, 1] == pytest.approx(-0.03)
    assert not frames["truth"].row_times.any() and frames["display"].row_times is None
    # The turn is seen: the frontal image differs, and the display's misregistration grows.
    assert not np.array_equal(frames["frontal"].colour, still.frames["frontal"].colour)
    grown = turning.metrics["display"]["misregistration_arcmin"]["mean"]
    assert grown > still.metrics["display"]["misregistration_arcmin"]["mean"] + 5
    # das's own frontal camera has an instant shutter: the motion would change nothing.
    das = seethru.Scene.load(REPO / "scenes" / "das.toml")
    with pytest.raises(ValueError, match="yaw_rate"):
        seethru.run(das, yaw_rate=20.0, **small)
