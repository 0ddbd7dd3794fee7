"""seethru.capture and seethru.score: a built-in method's own map scores as run measures it."""

import pathlib
import sys

import numpy as np
import pytest

import seethru
from conftest import REPO, SCENE

sys.path.insert(0, str(REPO / "examples" / "python"))
from planar_method import planar_map  # noqa: E402  (the numpy planar crop of examples/)

SIZES = dict(width=160, frontal_width=320, back_width=160, spp=1)


def test_the_numpy_planar_map_scores_as_run_planar():
    scene = seethru.Scene.load(SCENE)
    cap = seethru.capture(scene, **SIZES)
    w, h = cap.display_resolution
    assert cap.frontal.colour.shape == (cap.frontal.height, cap.frontal.width, 3)
    assert cap.calibration["display"]["resolution_px"] == [w, h]
    m = planar_map(cap.calibration, {"head": cap.head})
    assert m.shape == (h, w, 2)
    scored = seethru.score(cap, map=m)
    builtin = seethru.run(scene, method="planar", **SIZES)
    # Same truth and driver views; the same pixels counted.
    for view in ("truth", "occluded"):
        assert np.array_equal(scored.frames[view].colour, builtin.frames[view].colour)
    for key in ("display_pixels", "blank_pixels", "undefined_pixels"):
        assert scored.metrics[key] == builtin.metrics[key], key
    assert scored.metrics["external_method"]["display_from"] == "map"
    # Misregistration per pixel: equal but where float32 rounding of the map crosses a
    # frontal pixel edge (a neighbour shown instead, at most one diagonal pixel away).
    fx = cap.calibration["frontal"]["K"][0][0]
    quantum = np.degrees(np.arctan(np.sqrt(2) / fx)) * 60
    a, b = scored.misregistration, builtin.misregistration
    both = np.isfinite(a) | np.isfinite(b)
    assert both.sum() > 100
    differ = both & (a != b)
    assert differ.sum() * 20 <= both.sum()
    assert np.all(np.abs(a[both] - b[both]) <= quantum)


def test_a_shifted_map_is_worse_and_a_bad_map_is_refused():
    scene = seethru.Scene.load(SCENE)
    cap = seethru.capture(scene, **SIZES)
    m = planar_map(cap.calibration, {"head": cap.head})
    good = seethru.score(cap, map=m).metrics["display"]["misregistration_arcmin"]["mean"]
    shifted = m.copy()
    shifted[..., 0] += 8.0  # eight frontal pixels to the right
    worse = seethru.score(cap, map=shifted).metrics["display"]["misregistration_arcmin"]["mean"]
    assert worse > good + 1.0
    with pytest.raises(ValueError, match=r"the map is \d+×\d+ display pixels"):
        seethru.score(cap, map=m[:-1])
    with pytest.raises(ValueError, match="score needs map=, display_image= or both"):
        seethru.score(cap)


def _metrics_of(folder: pathlib.Path) -> dict:
    import json

    return json.loads((folder / "metrics.json").read_text())


def test_python_scores_a_folder_the_cli_captured_and_the_cli_a_folder_python_saved(tmp_path):
    from conftest import seethru_cli

    flags = ["--width", "96", "--frontal-width", "192", "--back-width", "96", "--spp", "1"]
    cli = seethru_cli("capture", str(SCENE), "--out", str(tmp_path / "cli_cap"), *flags, "--depth")
    assert cli.returncode == 0, cli.stderr
    loaded = seethru.load_capture(tmp_path / "cli_cap")
    assert loaded.inverse_depth is not None
    m = planar_map(loaded.calibration, {"head": loaded.head})
    np.save(tmp_path / "map.npy", m.astype(np.float32))
    # Python's score of the CLI's folder is the CLI's score of it.
    cli = seethru_cli("score", str(tmp_path / "cli_cap"), "--map", str(tmp_path / "map.npy"), "--out", str(tmp_path / "s1"))
    assert cli.returncode == 0, cli.stderr
    scored = seethru.score(loaded, map=m)
    assert scored.metrics == _metrics_of(tmp_path / "s1")
    import json

    assert scored.hazards == json.loads((tmp_path / "s1" / "hazards.json").read_text())
    # The other way: a capture made in Python, saved, is the folder the CLI captures.
    scene = seethru.Scene.load(SCENE)
    cap = seethru.capture(scene, depth=True, width=96, frontal_width=192, back_width=96, spp=1)
    assert cap.fingerprint == loaded.fingerprint
    cap.save(tmp_path / "py_cap")
    cli = seethru_cli("score", str(tmp_path / "py_cap"), "--map", str(tmp_path / "map.npy"), "--out", str(tmp_path / "s2"))
    assert cli.returncode == 0, cli.stderr
    assert _metrics_of(tmp_path / "s2") == _metrics_of(tmp_path / "s1")


def test_a_capture_of_a_scene_changed_in_memory_is_not_saved(tmp_path):
    scene = seethru.Scene.load(SCENE)
    x, y, z = scene.eye
    scene.eye = (x + 0.01, y, z)
    cap = seethru.capture(scene, width=32, spp=1)
    with pytest.raises(ValueError, match="changed in memory"):
        cap.save(tmp_path / "c")
    assert not (tmp_path / "c").exists()
    # Not a capture folder: named.
    with pytest.raises(OSError, match="capture.json"):
        seethru.load_capture(tmp_path / "nothing")


def test_an_image_alone_says_misregistration_needs_a_map():
    scene = seethru.Scene.load(SCENE)
    cap = seethru.capture(scene, width=48, spp=1)
    w, h = cap.display_resolution
    image = np.full((h, w, 3), 0.5, np.float32)
    alone = seethru.score(cap, display_image=image).metrics
    assert "misregistration_needs_a_map" in alone
    assert alone["external_method"]["display_from"] == "image"
    m = planar_map(cap.calibration, {"head": cap.head}).astype(np.float32)
    with_map = seethru.score(cap, map=m, display_image=image).metrics
    assert "misregistration_needs_a_map" not in with_map
    assert with_map["external_method"]["display_from"] == "map and image"


def test_a_display_image_of_codes_is_shown_through_the_displays_transfer():
    # das_dusk: a coded camera and an sRGB display of 1000 cd/m² (black 0.5).
    scene = seethru.Scene.load(REPO / "scenes" / "das_dusk.toml")
    cap = seethru.capture(scene, width=48, frontal_width=160, spp=1)
    w, h = cap.display_resolution
    image = np.full((h, w, 3), 0.5, np.float32)
    linear = seethru.score(cap, display_image=image).metrics["luminance"]["display"]
    codes = seethru.score(cap, display_image=image, display_codes=True).metrics["luminance"]["display"]
    # The display's sRGB curve of code 0.5 is 0.214 of its range: codes give less light than
    # linear 0.5, by the curve (and the light its face reflects, the same in both).
    srgb = ((0.5 + 0.055) / 1.055) ** 2.4
    step = 999.5 * (0.5 - srgb)
    assert abs((linear["seethru_mean_cd_m2"] - codes["seethru_mean_cd_m2"]) - step) < 0.01 * step
    with pytest.raises(ValueError, match="display_codes says what display_image= holds"):
        seethru.score(cap, map=planar_map(cap.calibration, {"head": cap.head}), display_codes=True)
