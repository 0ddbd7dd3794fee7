"""seethru.compare, seethru.ratio and seethru.analyze against the commands' JSON."""

import json

import numpy as np
import pytest

import seethru
from conftest import SCENE, seethru_cli

# What a row measures of the machine rather than computes (wall-clock cost).
TIMED = ("ms", "seconds", "time")


def untimed(value):
    """A JSON value without its timing entries (keys naming milliseconds or seconds)."""
    if isinstance(value, dict):
        return {k: untimed(v) for k, v in value.items() if not any(t in k for t in TIMED)}
    if isinstance(value, list):
        return [untimed(v) for v in value]
    return value


def test_analyze_matches_the_cli():
    cli = seethru_cli("analyze", "--json", "--d1", "0.9", "--d2", "inf", "--bh", "0.2")
    assert cli.returncode == 0, cli.stderr
    expected = json.loads(cli.stdout)
    got = seethru.analyze(d1=0.9, d2=float("inf"), bh=0.2)
    assert got == expected  # every block, lens_and_eyes included
    lens = ["--height", "0.3", "--k1", "-0.2", "--ipd", "0.06", "--theta-f", "60", "--frontal-px", "800"]
    cli = seethru_cli("analyze", "--json", "--d1", "0.7", "--d2", "2.5", "--bh", "-0.1", *lens)
    assert cli.returncode == 0, cli.stderr
    got = seethru.analyze(d1=0.7, d2=2.5, bh=-0.1, height=0.3, k1=-0.2, ipd=0.06, theta_f=60, frontal_px=800)
    assert got == json.loads(cli.stdout)
    # The parameters reach the closed forms: another eye distance, other values.
    assert seethru.analyze(d1=0.5, d2=float("inf"), bh=0.2)["evaluation"] != got["evaluation"]


def test_ratio_matches_the_cli():
    args = ["--L", "1.0", "--b1", "0.25", "--d2", "2.0", "--d1", "0.8", "--bh", "0.1"]
    cli = seethru_cli("ratio", "occlusion", *args, "--width", "200", "--json")
    assert cli.returncode == 0, cli.stderr
    got = seethru.ratio("occlusion", L=1.0, b1=0.25, d2=2.0, d1=0.8, bh=0.1, width=200)
    assert untimed(got) == untimed(json.loads(cli.stdout))


def test_compare_matches_the_cli(tmp_path):
    out = tmp_path / "compare"
    cli = seethru_cli(
        "compare", str(SCENE), "--methods", "planar-inf,ground", "--width", "96", "--spp", "1",
        "--out", str(out),
    )
    assert cli.returncode == 0, cli.stderr
    expected = json.loads((out / "compare.json").read_text())
    scene = seethru.Scene.load(SCENE)
    got = seethru.compare(scene, methods=["planar-inf", "ground"], width=96, spp=1)
    assert untimed(got["rows"]) == untimed(expected["rows"])
    assert set(got["strips"]) == {"planar-inf", "ground"}
    strip = got["strips"]["ground"]
    assert strip.dtype == np.uint8 and strip.ndim == 3 and strip.shape[2] == 3


def test_measure_options_are_checked():
    with pytest.raises(ValueError, match=r"L is required"):
        seethru.ratio("occlusion", b1=0.25, d2=2.0, d1=0.8, bh=0.1)
    with pytest.raises(ValueError, match=r'setup "tilt" is not one of occlusion, foreshortening'):
        seethru.ratio("tilt")
    with pytest.raises(ValueError, match=r"d1=0 is out of range"):
        seethru.analyze(d1=0)
    with pytest.raises(ValueError, match=r'unknown option "method"'):
        seethru.compare(seethru.Scene.load(SCENE), method="planar")
