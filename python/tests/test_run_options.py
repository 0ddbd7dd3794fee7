"""`seethru.run`, `seethru.capture` and `seethru.compare` take their commands' flags as
keywords, refuse the same settings with the same words (keyword names for flags), and
compute what their commands write."""

import json
import re

import pytest

import seethru
from conftest import REPO, SCENE, seethru_cli

# Flags that name files, threads or progress, or are another argument in Python.
NOT_KEYWORDS = {"out", "quiet", "calibration", "threads", "exr", "heatmap_max", "methods", "help"}


def keyword_names(text: str) -> str:
    """The command line's message in Python's words (`--head-bias-cm` → `head_bias_cm`)."""
    return re.sub(r"(?<![\w-])--([a-z0-9][a-z0-9-]*)", lambda m: m.group(1).replace("-", "_"), text)


def cli_flags(command: str) -> set[str]:
    out = seethru_cli(command, "--help").stdout
    flags = {m.group(1).replace("-", "_") for m in re.finditer(r"^\s+(?:-\w, )?--([a-z0-9-]+)", out, re.M)}
    return flags - NOT_KEYWORDS


def listed_keywords(call) -> set[str]:
    with pytest.raises(ValueError) as raised:
        call(no_such_option=1)
    listed = str(raised.value).split("the options are ", 1)[1]
    return {k.strip() for k in listed.split(",")} - {"methods"}


@pytest.mark.parametrize("command", ["run", "capture", "compare"])
def test_each_function_takes_exactly_its_commands_flags(command):
    scene = seethru.Scene.load(SCENE)
    call = {
        "run": lambda **k: seethru.run(scene, **k),
        "capture": lambda **k: seethru.capture(scene, **k),
        "compare": lambda **k: seethru.compare(scene, **k),
    }[command]
    assert listed_keywords(call) == cli_flags(command)


# (Python call, the same on the command line): each refused with the same words.
REFUSED = [
    ("run", dict(method="none", head_bias_cm=(1, 0, 0)), ["--method", "none", "--head-bias-cm", "1,0,0"]),
    ("run", dict(method="depth", d2=5), ["--method", "depth", "--d2", "5"]),
    ("run", dict(fill="inpaint"), ["--fill", "inpaint"]),
    ("run", dict(ipd=0.07), ["--ipd", "0.07"]),
    ("run", dict(depth_noise=0.01), ["--depth-noise", "0.01"]),
    ("run", dict(require_confident_head=True), ["--require-confident-head"]),
    ("capture", dict(depth_noise=0.01), ["--depth-noise", "0.01"]),
    ("capture", dict(depth=True, require_confident_head=True), ["--depth", "--require-confident-head"]),
    ("capture", dict(feature_width=0.07), ["--feature-width", "0.07"]),
    ("compare", dict(methods=["planar-inf"], depth_noise=0.01), ["--methods", "planar-inf", "--depth-noise", "0.01"]),
    ("compare", dict(methods=["ground"], seed=3), ["--methods", "ground", "--seed", "3"]),
]


@pytest.mark.parametrize("command,keywords,flags", REFUSED)
def test_a_setting_the_call_would_ignore_is_refused_as_on_the_command_line(tmp_path, command, keywords, flags):
    scene = seethru.Scene.load(SCENE)
    keywords = dict(width=16, spp=1, **keywords)
    with pytest.raises(ValueError) as raised:
        getattr(seethru, command)(scene, **keywords)
    cli = seethru_cli(command, str(SCENE), "--out", str(tmp_path / "o"), "--width", "16", "--spp", "1", *flags)
    assert cli.returncode != 0
    said = cli.stderr.strip().removeprefix("error: ")
    assert str(raised.value) == keyword_names(said).replace("other flags", "other options")
    assert "--" not in str(raised.value)


def test_settings_a_call_reads_are_taken():
    scene = seethru.Scene.load(SCENE)
    # The default methods of compare include plane-fit and the depth methods: their sensor's
    # settings are read.
    rows = seethru.compare(scene, methods=["planar-inf", "depth-tof"], depth_noise=0.0, width=16, spp=1)["rows"]
    assert [r["method"] for r in rows] == ["planar-inf", "depth-tof"]
    capture = seethru.capture(scene, depth=True, depth_sensor="tof", depth_noise=0.0, width=16, spp=1)
    assert capture.inverse_depth is not None


def test_run_computes_the_hazards_seethru_run_writes(tmp_path):
    scene_path = REPO / "scenes" / "left_turn.toml"
    shown = {}
    for bound in (0.001, 600):
        flags = ["--width", "96", "--spp", "1", "--hazard-bound-arcmin", str(bound)]
        cli = seethru_cli("run", str(scene_path), "--out", str(tmp_path / str(bound)), *flags)
        assert cli.returncode == 0, cli.stderr
        written = json.loads((tmp_path / str(bound) / "hazards.json").read_text())
        run = seethru.run(seethru.Scene.load(scene_path), width=96, spp=1, hazard_bound_arcmin=bound)
        assert run.hazards == written
        assert [o["name"] for o in run.hazards["objects"]] == ["pedestrian", "cyclist"]
        shown[bound] = sum(o["shown_pixels"] for o in run.hazards["objects"])
    # The bound is read: the pedestrian's hidden pixels are shown within 600′, not 0.001′.
    assert shown[0.001] < shown[600]
