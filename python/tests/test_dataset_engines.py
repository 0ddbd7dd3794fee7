"""examples/dataset/engines.py: a dataset made by Ray tasks (ray.init(num_cpus=2)) and by a
Dask LocalCluster of two workers, a task per shard through `seethru.dataset`, is a single
`seethru dataset` process's, file for file."""

import os
import subprocess

import pytest

from conftest import REPO, example_module, folder_files as files

BIN = os.environ.get("SEETHRU_BIN", "seethru")


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    base = tmp_path_factory.mktemp("engines")
    spec = base / "spec.toml"
    spec.write_text(
        f'scene = "{REPO / "scenes/das.toml"}"\nsamples = 4\nseed = 3\n'
        '[options]\nwidth = 48\nspp = 1\n[draw]\ntheta_f = { uniform = [40, 60] }\n'
    )
    one = base / "one"
    done = subprocess.run([BIN, "dataset", str(spec), "--out", str(one), "--quiet"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return base, str(spec), files(one)


@pytest.mark.parametrize("engine", ["ray", "dask"])
def test_an_engine_makes_the_files_one_process_makes(reference, engine):
    base, spec, want = reference
    out = str(base / engine)
    run = getattr(example_module("dataset/engines.py"), f"on_{engine}")
    made = run(spec, out, 2, 2)
    assert [m["made"] for m in made] == [2, 2], made
    got = files(out)
    assert sorted(got) == sorted(want)
    assert all(got[k] == want[k] for k in want), [k for k in want if got[k] != want[k]]
