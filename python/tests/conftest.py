"""Fixtures: the command line's own outputs for the same scene and options, to compare with.

SEETHRU_BIN names the `seethru` binary (tests/python.rs passes cargo's); SEETHRU_REPO the
repository root (default: two folders above this one).
"""

import importlib.util
import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(os.environ.get("SEETHRU_REPO", pathlib.Path(__file__).resolve().parents[2]))
SCENE = REPO / "scenes" / "das.toml"


def folder_files(folder):
    """Every file under `folder`: its path relative to `folder` → its bytes."""
    out = {}
    for root, _, names in os.walk(folder):
        for name in names:
            path = os.path.join(root, name)
            with open(path, "rb") as f:
                out[os.path.relpath(path, folder)] = f.read()
    return out


def example_module(relative):
    """A Python file of examples/ (`dataset/loaders.py`) imported as a module, as a reader
    who copies it would use it."""
    path = REPO / "examples" / relative
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
# A small valid scene (tests/common/mod.rs's MINIMAL): a ground plane, a sphere, the obstacle.
MINIMAL = """
[obstacle]
center = [0.0, 1.2, -0.8]
width = 0.3
height = 0.4

[camera.driver]
position = [0.0, 1.2, 0.0]
look_at = [0.0, 1.2, -10.0]
resolution = [64, 36]

[camera.frontal]
resolution = [64, 36]

[camera.back]
resolution = [32, 24]

[[material]]
name = "grey"
color = [0.5, 0.5, 0.5]

[[object]]
name = "ground"
kind = "plane"
material = "grey"
size = [100.0, 100.0]

[[object]]
name = "ball"
kind = "sphere"
material = "grey"
radius = 1.0
translate = [0.0, 1.0, -10.0]
"""
# Small and quick, with several samples so that colour averaging is exercised.
WIDTH, SPP = 160, 3


def seethru_cli(*args: str) -> subprocess.CompletedProcess:
    binary = os.environ.get("SEETHRU_BIN", str(REPO / "target" / "release" / "seethru"))
    return subprocess.run([binary, "--quiet", *args], capture_output=True, text=True)


@pytest.fixture(scope="session")
def cli_render(tmp_path_factory) -> pathlib.Path:
    out = tmp_path_factory.mktemp("render")
    views = [a for v in ("truth", "occluded", "frontal", "back") for a in ("--view", v)]
    done = seethru_cli("render", str(SCENE), *views, "--width", str(WIDTH), "--spp", str(SPP), "--out", str(out))
    assert done.returncode == 0, done.stderr
    return out


@pytest.fixture(scope="session")
def cli_run(tmp_path_factory) -> pathlib.Path:
    out = tmp_path_factory.mktemp("run")
    done = seethru_cli(
        "run", str(SCENE), "--width", str(WIDTH), "--spp", str(SPP),
        "--method", "planar", "--d2", "auto", "--out", str(out), "--exr", "all",
    )
    assert done.returncode == 0, done.stderr
    return out
