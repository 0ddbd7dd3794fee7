"""examples/dataset/loaders.py on a dataset that `seethru dataset` makes: the samples' arrays
are the files' (PNG and EXR), the draws and metrics the manifest's."""

import os
import subprocess

import numpy as np
import OpenEXR

from conftest import REPO, example_module

BIN = os.environ.get("SEETHRU_BIN", "seethru")


def test_seethru_pairs_reads_each_sample_as_its_files_say(tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text(
        f'scene = "{REPO / "scenes/das.toml"}"\nsamples = 3\nseed = 5\n'
        '[options]\nwidth = 48\nspp = 1\n[draw]\nmethod = { one_of = ["planar", "plane-fit"] }\n'
    )
    out = tmp_path / "d"
    done = subprocess.run([BIN, "dataset", str(spec), "--out", str(out), "--quiet"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    pairs = example_module("dataset/loaders.py").SeethruPairs(str(out))
    assert len(pairs) == 3 and pairs.draws == ["method"]
    import cv2

    for i in range(3):
        s = pairs[i]
        folder = out / "samples" / f"{i:06d}"
        truth = cv2.imread(str(folder / "truth.png"))[:, :, ::-1]
        assert s["truth"].shape == truth.shape and s["truth"].dtype == np.float32
        assert np.array_equal(np.round(s["truth"] * 255).astype(np.uint8), truth)
        with OpenEXR.File(str(folder / "misregistration.exr")) as f:
            y = f.channels()["Y"].pixels
        assert np.array_equal(np.isnan(s["misregistration"]), np.isnan(y))
        assert np.nanmean(s["misregistration"]) == np.nanmean(y)
        # The manifest's mean is metrics.json's, which is the map's mean over its values.
        assert abs(s["metrics"]["misregistration_mean_arcmin"] - float(np.nanmean(y.astype(np.float64)))) < 1e-3
        assert s["draws"]["method"] in ("planar", "plane-fit")


def test_the_parquet_manifest_is_the_csv_with_types(tmp_path):
    import csv
    import math

    import pyarrow.parquet as pq

    spec = tmp_path / "spec.toml"
    spec.write_text(
        f'scene = "{REPO / "scenes/das.toml"}"\nsamples = 3\nseed = 9\n'
        '[options]\nwidth = 48\nspp = 1\n[draw]\nmethod = { one_of = ["planar", "plane-fit"] }\n'
        'd2 = { one_of = ["inf", "6"] }\ntheta_f = { uniform = [40, 60] }\nhead = { one_of = ["oracle", "estimated"] }\n'
    )
    out = tmp_path / "d"
    done = subprocess.run([BIN, "dataset", str(spec), "--out", str(out), "--quiet"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    table = pq.read_table(out / "manifest.parquet")
    with open(out / "manifest.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert table.column_names == list(rows[0].keys())
    types = {f.name: str(f.type) for f in table.schema}
    assert types["sample"] == "int64" and types["theta_f"] == "double" and types["method"] == "string"
    assert types["d2"] == "double"  # "inf" and "6": numbers both (inf a DOUBLE's infinity)
    assert types["head"] == "string"
    for got, want in zip(table.to_pylist(), rows):
        for name, text in want.items():
            value = got[name]
            if types[name] in ("double", "int64"):
                assert (value is None and text == "") or value == float(text) or (math.isnan(value) and text == "NaN"), (name, value, text)
            else:
                assert value == (text or None), (name, value, text)
