"""seethru.sequence with the command line's loop options: frame for frame frames.csv's."""

import csv
import math
import re

import pytest

import seethru
from conftest import REPO, SCENE, seethru_cli

# Options in Python's words and the command line's, one run each, every frame compared.
# Lean, vehicle motion, two camera latencies, tracking latency, prediction, re-projection,
# the tracker model's head with jitter, a fixed working distance, display_hz below fps.
LOOP = dict(duration=0.1, fps=40, display_hz=20, width=96, head="lean", lean_cm=8,
            lean_at=0.02, lean_s=0.06, speed=30, yaw_rate=10, latency_camera=[0, 25],
            latency_tracking=10, predict="constant-velocity", reproject=True,
            head_source="model", head_jitter_cm=0.5, seed=7, d2=5.0)
LOOP_CLI = ["--duration", "0.1", "--fps", "40", "--display-hz", "20", "--width", "96",
            "--head", "lean", "--lean-cm", "8", "--lean-at", "0.02", "--lean-s", "0.06",
            "--speed", "30", "--yaw-rate", "10", "--latency-camera", "0,25",
            "--latency-tracking", "10", "--predict", "constant-velocity", "--reproject",
            "--head-source", "model", "--head-jitter-cm", "0.5", "--seed", "7", "--d2", "5"]
# A recorded head path, the image-based head estimate with a bias, d2 auto, the Kalman
# prediction, another filter, the sizes of the cameras.
PATH = REPO / "scenes" / "head_path_example.csv"
ESTIMATED = dict(duration=0.05, fps=40, width=96, head_path=str(PATH), head_source="estimated",
                 back_width=320, feature_width=0.066, head_bias_cm=(0.5, 0, 0), d2="auto",
                 predict="kalman", filter="bicubic", frontal_width=128, height=60)
ESTIMATED_CLI = ["--duration", "0.05", "--fps", "40", "--width", "96", "--head-path", str(PATH),
                 "--head-source", "estimated", "--back-width", "320", "--feature-width", "0.066",
                 "--head-bias-cm", "0.5,0,0", "--d2", "auto", "--predict", "kalman",
                 "--filter", "bicubic", "--frontal-width", "128", "--height", "60"]


def cli_rows(tmp_path, args):
    """frames.csv of every latency's sequence (whole driver views, as Python renders)."""
    done = seethru_cli("sequence", str(SCENE), *args, "--frames", "exr", "--out", str(tmp_path))
    assert done.returncode == 0, done.stderr
    rows = []
    for folder in sorted(tmp_path.glob("latency_*ms"), key=lambda p: float(p.name[8:-2])):
        with open(folder / "frames.csv") as f:
            rows += list(csv.DictReader(f))
    return rows


def same_as_cli(steps, rows):
    assert len(steps) == len(rows) > 1
    for s, r in zip(steps, rows):
        at = (s.latency_camera, s.frame)
        assert s.latency_camera == float(r["latency_camera_ms"]), at
        assert s.frame == int(r["frame"]) and s.time == float(r["t_s"]), at
        assert s.refresh_time == float(r["refresh_s"]) and s.head_time == float(r["head_sample_s"]), at
        for axis, i in (("x", 0), ("y", 1), ("z", 2)):
            for name in ("true", "estimated", "used"):
                assert getattr(s, f"eye_{name}")[i] == float(r[f"eye_{name}_{axis}_m"]), (at, name)
            assert s.vehicle_position[i] == float(r[f"vehicle_{axis}_m"]), at
        assert s.vehicle_yaw_deg == float(r["vehicle_yaw_deg"]), at
        assert (s.d2_used if s.d2_used is not None else math.inf) == float(r["d2_m"]), at
        confidence = float(r["head_confidence"])
        assert (s.head_confidence is None) == math.isnan(confidence), at
        if s.head_confidence is not None:
            assert s.head_confidence == confidence, at
        for name in ("head_yaw_deg", "head_fit_margin", "head_yaw_true_deg"):
            value = float(r[name])
            assert (getattr(s, name) is None) == math.isnan(value), (at, name)
            if getattr(s, name) is not None:
                assert getattr(s, name) == value, (at, name)
        m = s.metrics["display"]["misregistration_arcmin"]
        assert m["mean"] == float(r["misregistration_mean_arcmin"]), at
        assert m["p95"] == float(r["misregistration_p95_arcmin"]), at
        assert s.metrics["display"]["psnr_db"] == float(r["psnr_db"]), at


def test_the_loop_options_give_the_cli_frames(tmp_path):
    scene = seethru.Scene.load(SCENE)
    steps = list(seethru.sequence(scene, **LOOP))
    same_as_cli(steps, cli_rows(tmp_path, LOOP_CLI))
    assert [s.latency_camera for s in steps] == [0.0] * 4 + [25.0] * 4
    assert steps[4].capture_time == pytest.approx(steps[4].refresh_time - 0.025)
    # The options were read: without them the eyes and the vehicle differ.
    plain = list(seethru.sequence(scene, duration=0.1, fps=40, width=96))
    assert plain[-1].vehicle_position != steps[3].vehicle_position
    assert plain[-1].eye_used != steps[3].eye_used
    # Jitter of the model's head estimate follows the seed.
    other = next(iter(seethru.sequence(scene, **{**LOOP, "seed": 8})))
    assert other.eye_estimated != steps[0].eye_estimated


def test_the_estimated_head_options_give_the_cli_frames(tmp_path):
    scene = seethru.Scene.load(SCENE)
    steps = list(seethru.sequence(scene, **ESTIMATED))
    same_as_cli(steps, cli_rows(tmp_path, ESTIMATED_CLI))
    assert all(s.head_confidence is not None and s.d2_used is not None for s in steps)
    assert steps[0].truth.width == 96 and steps[0].truth.height == 60


def test_the_mesh_face_steps_carry_the_yaw_fit(tmp_path):
    # das_mesh_head ([camera.driver] face = "mesh"): the estimate is the yaw fit's, its yaw
    # and margin on each Step as in frames.csv; das's ellipsoid face has none.
    mesh = REPO / "scenes" / "das_mesh_head.toml"
    options = dict(duration=0.05, fps=40, width=96, height=60, frontal_width=128,
                   head_source="estimated", head="sway", sway_cm=5)
    steps = list(seethru.sequence(seethru.Scene.load(mesh), **options))
    done = seethru_cli("sequence", str(mesh), "--duration", "0.05", "--fps", "40", "--width", "96",
                       "--height", "60", "--frontal-width", "128", "--head-source", "estimated",
                       "--head", "sway", "--sway-cm", "5", "--frames", "exr", "--out", str(tmp_path))
    assert done.returncode == 0, done.stderr
    with open(tmp_path / "latency_0ms" / "frames.csv") as f:
        same_as_cli(steps, list(csv.DictReader(f)))
    assert all(s.head_yaw_deg is not None and s.head_fit_margin is not None for s in steps)
    assert all(abs(s.head_yaw_deg - s.head_yaw_true_deg) < 2.0 for s in steps)
    plain = next(iter(seethru.sequence(seethru.Scene.load(SCENE), duration=0.025, fps=40,
                                       width=32, head_source="estimated")))
    assert plain.head_yaw_deg is None and plain.head_yaw_true_deg is None


def test_a_predictor_replaces_the_prediction_of_every_latency():
    scene = seethru.Scene.load(SCENE)
    asked = []

    def spy(info):
        asked.append((info["latency_camera"], info["frame"]))
        return info["eye_true"]

    steps = list(seethru.sequence(scene, predictor=spy, **{**LOOP, "display_hz": 40}))
    assert asked == [(ms, k) for ms in (0.0, 25.0) for k in range(4)]
    assert all(s.eye_used == s.eye_true for s in steps)


def test_ignored_and_bad_options_are_refused_as_on_the_command_line():
    scene = seethru.Scene.load(SCENE)
    cases = [
        (dict(sway_cm=2), "sway_cm is read only with head sway (and no head_path); with the other options given it would be ignored: remove it"),
        (dict(method="none", predict="kalman"), "predict is read only by the methods that compensate for the eye (not method none)"),
        (dict(method="none", reproject=True), "reproject is read only by method planar"),
        (dict(back_width=100), "back_width is read only with head_source estimated"),
        (dict(seed=3), "seed is read only with head_jitter_cm > 0"),
        (dict(hazard_bound_arcmin=5), "hazard_bound_arcmin is read only for a scene with an object marked `hazard = true`"),
        (dict(head="sway", head_path=str(PATH)), "head_path cannot be used with head"),
        (dict(latency_camera=[10, 10.0000001]), "latencies 10 and 10.0000001 ms are the same to 6 digits: give each once"),
        (dict(latency_camera=20000), "latency_camera=20000 is out of range: must be a number in [0, 10000]"),
        (dict(predict="psychic"), 'predict="psychic" is not one of none, constant-velocity, kalman'),
        (dict(head_source="x"), 'head_source="x" is not one of oracle, estimated, model'),
        (dict(d2="near"), "d2="),
        (dict(reproject="yes"), "reproject: True or False is needed"),
        (dict(max_memory=1e-6), "GiB"),
    ]
    for options, message in cases:
        with pytest.raises(ValueError, match=re.escape(message)):
            seethru.sequence(scene, duration=0.05, width=32, **options)
    # The command line refuses the same with the flag names.
    done = seethru_cli("sequence", str(SCENE), "--sway-cm", "2", "--out", "/nonexistent/x")
    assert "--sway-cm is read only with --head sway (and no --head-path)" in done.stderr
    # Given False, a switch is absent (as a flag left off): no refusal.
    assert len(seethru.sequence(scene, duration=0.05, width=32, method="none", reproject=False)) >= 1
    with pytest.raises(OSError, match="missing.csv"):
        seethru.sequence(scene, head_path=str(REPO / "missing.csv"))


def test_hazards_follow_the_bound_as_on_the_command_line(tmp_path):
    # hazards.md's turn: the pedestrian goes behind the pillar from t = 0.4 s.
    turn = REPO / "scenes" / "left_turn.toml"
    done = seethru_cli("sequence", str(turn), "--duration", "1", "--fps", "5", "--width", "96",
                       "--speed", "10", "--yaw-rate", "15.9", "--hazard-bound-arcmin", "0.01",
                       "--frames", "exr", "--out", str(tmp_path))
    assert done.returncode == 0, done.stderr
    with open(tmp_path / "latency_0ms" / "frames.csv") as f:
        rows = list(csv.DictReader(f))
    scene = seethru.Scene.load(turn)
    options = dict(duration=1, fps=5, width=96, speed=10, yaw_rate=15.9)
    steps = list(seethru.sequence(scene, hazard_bound_arcmin=0.01, **options))
    assert len(steps) == len(rows) == 5
    for s, r in zip(steps, rows):
        assert [h["frame"]["name"] for h in s.hazards] == ["pedestrian", "cyclist"]
        for h in s.hazards:
            prefix = f"hazard_{h['frame']['name']}_"
            assert h["frame"]["truth_pixels"] == float(r[prefix + "truth_pixels"])
            assert h["frame"]["hidden_pixels"] == float(r[prefix + "hidden_pixels"])
            if h["frame"]["truth_pixels"]:
                seen_on = h["seen_on_pixels"] / h["frame"]["truth_pixels"]
                assert seen_on == float(r[prefix + "seen_display_on"]), (s.time, h)
    hidden = [sum(h["frame"]["hidden_pixels"] for h in s.hazards) for s in steps]
    assert hidden[0] == 0 and hidden[-1] > 0
    # A bound no misregistration reaches counts every shown hazard pixel: more are seen.
    looser = list(seethru.sequence(scene, hazard_bound_arcmin=10000, **options))
    seen = lambda steps: sum(h["seen_on_pixels"] for s in steps for h in s.hazards)
    assert seen(looser) > seen(steps)
