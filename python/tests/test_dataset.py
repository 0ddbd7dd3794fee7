"""seethru.dataset: the command line's `seethru dataset`, to the same bytes, with its refusals
as exceptions."""

import os
import subprocess
import warnings

import pytest

import seethru
from conftest import REPO, folder_files

BIN = os.environ.get("SEETHRU_BIN", "seethru")

SPEC = (
    f'scene = "{REPO / "scenes/das.toml"}"\nsamples = 4\nseed = 11\n'
    '[options]\nwidth = 40\nspp = 1\n'
    '[draw]\nmethod = { one_of = ["planar", "plane-fit"] }\neye_x = { normal = [0, 0.03] }\n'
)


def cli(*args):
    done = subprocess.run([BIN, "dataset", *map(str, args), "--quiet"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    base = tmp_path_factory.mktemp("dataset")
    spec = base / "spec.toml"
    spec.write_text(SPEC)
    cli(spec, "--out", base / "cli")
    return base, spec, folder_files(base / "cli")


def test_python_makes_the_command_lines_files_and_says_what_it_did(made):
    base, spec, want = made
    out = base / "py"
    result = seethru.dataset(spec, out, threads=1)
    assert folder_files(out) == want
    assert (result["made"], result["kept"], result["done"], result["samples"]) == (4, 0, 4, 4)
    assert result["manifest"] == out / "manifest.csv"
    assert result["samples_per_second"] == pytest.approx(4 / result["seconds"])
    again = seethru.dataset(str(spec), str(out))
    assert (again["made"], again["kept"], again["samples_per_second"]) == (0, 4, None)
    assert folder_files(out) == want


def test_shards_from_python_and_the_command_line_merge_byte_for_byte(made):
    base, spec, want = made
    out = base / "mixed"
    first = seethru.dataset(spec, out, shard=(1, 2))
    assert (first["made"], first["done"], first["manifest"]) == (2, 2, None)
    assert not (out / "manifest.csv").exists()
    cli(spec, "--out", out, "--shard", "0/2")
    assert folder_files(out) == want
    # A sample lost after the fact is made again, by Python, to the same bytes.
    for name in os.listdir(out / "samples" / "000003"):
        os.remove(out / "samples" / "000003" / name)
    os.rmdir(out / "samples" / "000003")
    os.remove(out / "manifest.parquet")
    assert seethru.dataset(spec, out, shard="3/4")["made"] == 1
    assert folder_files(out) == want


def test_bad_arguments_raise_naming_the_argument_and_write_nothing(made, tmp_path):
    _, spec, _ = made
    out = tmp_path / "never"
    for kwargs, words in [
        (dict(shard="2/2"), "shard"),
        (dict(shard=(0, 0)), "shard"),
        (dict(shard=[0]), "shard"),
        (dict(exr="some"), "exr"),
        (dict(threads=0), "threads"),
    ]:
        with pytest.raises(ValueError, match=words):
            seethru.dataset(spec, out, **kwargs)
        assert not out.exists(), kwargs
    bad = tmp_path / "bad.toml"
    bad.write_text(SPEC.replace("seed = 11", "seed = 11\nsampels = 3"))
    with pytest.raises(ValueError, match=r"bad\.toml.*sampels"):
        seethru.dataset(bad, out)
    # A draw a run refuses is refused before anything is written, in Python's words.
    bad.write_text(SPEC + "band = { uniform = [0, 0] }\n")
    with pytest.raises(ValueError, match=r"sample 0 of 4.*band = 0"):
        seethru.dataset(bad, out)
    assert not out.exists()
    with pytest.raises(OSError, match="missing.toml"):
        seethru.dataset(tmp_path / "missing.toml", out)
    # Another spec's folder is refused.
    other = tmp_path / "other.toml"
    other.write_text(SPEC.replace("seed = 11", "seed = 12"))
    with pytest.raises(ValueError, match="another spec"):
        seethru.dataset(other, made[0] / "cli")


def test_a_doubtful_head_estimate_is_warned_per_sample(tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text(
        f'scene = "{REPO / "scenes/das.toml"}"\nsamples = 2\n'
        '[options]\nwidth = 40\nspp = 1\nhead = "estimated"\nmin_head_confidence = 1\n'
        '[draw]\neye_x = { uniform = [0.1, 0.15] }\n'
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = seethru.dataset(spec, tmp_path / "d")
    said = [str(w.message) for w in caught]
    assert said == result["warnings"] and said, result
    assert all(w.startswith("sample ") and "require_confident_head" in w and "--" not in w for w in said), said
