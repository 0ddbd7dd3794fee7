"""seethru.sequence: a sequence stepped from Python, with a predictor supplying the eye."""

import csv

import numpy as np
import pytest

import seethru
from conftest import SCENE, seethru_cli

# A short swaying sequence, small: every frame is a refresh (display_hz = fps).
OPTIONS = dict(duration=0.1, fps=40, head="sway", sway_cm=5, width=96, spp=1)
CLI = ["--duration", "0.1", "--fps", "40", "--head", "sway", "--sway-cm", "5", "--width", "96", "--spp", "1"]


@pytest.fixture(scope="module")
def cli_frames(tmp_path_factory):
    """frames.csv of the command line's oracle sequence with whole driver views."""
    out = tmp_path_factory.mktemp("sequence")
    done = seethru_cli("sequence", str(SCENE), *CLI, "--frames", "exr", "--out", str(out))
    assert done.returncode == 0, done.stderr
    with open(out / "latency_0ms" / "frames.csv") as f:
        return list(csv.DictReader(f))


def oracle(info):
    # The oracle head source: the true eye when the back image was taken.
    return info["eye_at_head_time"]


def biased(info):
    x, y, z = info["eye_at_head_time"]
    return (x + 0.03, y, z)


def test_a_true_eye_predictor_gives_the_cli_oracle_metrics(cli_frames):
    scene = seethru.Scene.load(str(SCENE))
    steps = list(seethru.sequence(scene, predictor=oracle, **OPTIONS))
    assert len(steps) == len(cli_frames) > 1
    for step, row in zip(steps, cli_frames):
        assert step.time == float(row["t_s"])
        m = step.metrics["display"]["misregistration_arcmin"]
        assert m["mean"] == float(row["misregistration_mean_arcmin"]), step.frame
        assert m["p95"] == float(row["misregistration_p95_arcmin"]), step.frame
        assert step.metrics["display"]["psnr_db"] == float(row["psnr_db"]), step.frame
        assert step.eye_used == step.eye_estimated
    # The head moves: the frames differ, so the comparison above compared something.
    means = {s.metrics["display"]["misregistration_arcmin"]["mean"] for s in steps}
    assert len({s.eye_true for s in steps}) == len(steps)
    truth = steps[0].truth.colour
    assert truth.shape == (steps[0].truth.height, steps[0].truth.width, 3) and truth.dtype == np.float32
    assert np.nanmax(steps[0].misregistration) > 0 or len(means) > 1


def test_a_biased_predictor_misregisters_more():
    scene = seethru.Scene.load(str(SCENE))
    asked = []

    def spy(info):
        asked.append(info["frame"])
        return biased(info)

    good = [s.metrics["display"]["misregistration_arcmin"]["mean"]
            for s in seethru.sequence(scene, predictor=oracle, **OPTIONS)]
    bad_steps = list(seethru.sequence(scene, predictor=spy, **OPTIONS))
    bad = [s.metrics["display"]["misregistration_arcmin"]["mean"] for s in bad_steps]
    assert asked == list(range(len(bad)))  # once per refresh, in order
    assert all(b > g + 1.0 for g, b in zip(good, bad)), (good, bad)
    s = bad_steps[0]
    assert s.eye_used[0] == pytest.approx(s.eye_true[0] + 0.03, abs=1e-12)
    assert s.eye_used != s.eye_estimated


def test_without_a_predictor_the_system_estimates(cli_frames):
    scene = seethru.Scene.load(str(SCENE))
    step = next(iter(seethru.sequence(scene, **OPTIONS)))
    assert step.metrics["display"]["misregistration_arcmin"]["mean"] == float(
        cli_frames[0]["misregistration_mean_arcmin"])


def test_bad_sequence_input_raises():
    scene = seethru.Scene.load(str(SCENE))
    with pytest.raises(ValueError, match="fps=0"):
        seethru.sequence(scene, fps=0)
    with pytest.raises(ValueError, match="unknown option"):
        seethru.sequence(scene, colour="red")
    with pytest.raises(ValueError, match="three numbers"):
        next(iter(seethru.sequence(scene, predictor=lambda info: "left", **OPTIONS)))


def test_flip_is_computed_only_when_asked(tmp_path):
    # As the command line's --flip: FLIP in every frame's metrics with flip=True, None (and
    # a note saying why) without it.
    out = tmp_path / "flip"
    done = seethru_cli("sequence", str(SCENE), *CLI, "--flip", "--out", str(out))
    assert done.returncode == 0, done.stderr
    with open(out / "latency_0ms" / "frames.csv") as f:
        rows = list(csv.DictReader(f))
    scene = seethru.Scene.load(str(SCENE))
    with_flip = list(seethru.sequence(scene, predictor=oracle, flip=True, **OPTIONS))
    without = list(seethru.sequence(scene, predictor=oracle, **OPTIONS))
    assert len(with_flip) == len(without) == len(rows) > 1
    for a, b, row in zip(with_flip, without, rows):
        assert a.metrics["display"]["flip_mean"] == float(row["flip"]) > 0
        assert b.metrics["display"]["flip_mean"] is None
        assert "flip_not_computed" in b.metrics and "flip_not_computed" not in a.metrics
        assert b.metrics["display"]["ssim"] == a.metrics["display"]["ssim"]
