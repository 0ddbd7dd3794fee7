"""Loaders for a `seethru dataset` folder (docs/guide/datasets.md).

    pairs = SeethruPairs("das_pairs")          # any Python: numpy arrays per sample
    loader = torch.utils.data.DataLoader(pairs, batch_size=4)   # PyTorch takes it as it is
    hf = hugging_face("das_pairs")             # a Hugging Face `datasets.Dataset`

Reading the PNGs needs OpenCV (`opencv-python-headless<5`); the misregistration map (an EXR)
needs the `OpenEXR` package. PyTorch and `datasets` are imported only by the functions that
use them. python/tests/test_dataset_loaders.py runs SeethruPairs on a real dataset.
"""

import csv
import os

import numpy as np

# The manifest's columns that are not draws (the rest before them are the sample's draws).
METRICS = [
    "misregistration_mean_arcmin",
    "misregistration_p95_arcmin",
    "coverage",
    "border_mean_arcmin",
    "psnr_db",
    "ssim",
    "display_pixels",
    "eye_error_m",
]


def read_manifest(folder):
    """The manifest's rows (dicts of text), one per sample, in sample order."""
    with open(os.path.join(folder, "manifest.csv"), newline="") as f:
        return list(csv.DictReader(f))


def number(text):
    """A manifest value as a float (an empty field, a metric with no value: NaN)."""
    return float(text) if text not in ("", None) else float("nan")


class SeethruPairs:
    """Sample i: {"truth", "seethru"}: float32 RGB in [0, 1], (h, w, 3); "misregistration":
    arc-minutes, (h, w), NaN off the display; "draws" and "metrics": the manifest's values.
    A map-style dataset: PyTorch's DataLoader takes it without a wrapper."""

    def __init__(self, folder, maps=True):
        self.folder, self.maps = folder, maps
        self.rows = read_manifest(folder)
        header = list(self.rows[0].keys()) if self.rows else []
        first_metric = header.index(METRICS[0]) if METRICS[0] in header else len(header)
        self.draws = header[1:first_metric]

    def __len__(self):
        return len(self.rows)

    def image(self, relative):
        import cv2

        bgr = cv2.imread(os.path.join(self.folder, relative), cv2.IMREAD_COLOR)
        if bgr is None:
            raise OSError(f"cannot read {relative} in {self.folder}")
        return (bgr[:, :, ::-1] / 255.0).astype(np.float32)

    def __getitem__(self, i):
        row = self.rows[i]
        sample = {
            "truth": self.image(row["truth_png"]),
            "seethru": self.image(row["seethru_png"]),
            "draws": {d: row[d] for d in self.draws},
            "metrics": {m: number(row[m]) for m in METRICS},
        }
        if self.maps:
            import OpenEXR

            with OpenEXR.File(os.path.join(self.folder, row["misregistration_exr"])) as f:
                sample["misregistration"] = f.channels()["Y"].pixels.astype(np.float32)
        return sample


def hugging_face(folder):
    """The manifest as a Hugging Face `datasets.Dataset`, its PNG paths decoded as images."""
    import datasets

    rows = read_manifest(folder)
    table = {k: [r[k] for r in rows] for k in rows[0]}
    for column in ("truth_png", "seethru_png"):
        table[column] = [os.path.join(folder, p) for p in table[column]]
    ds = datasets.Dataset.from_dict(table)
    return ds.cast_column("truth_png", datasets.Image()).cast_column("seethru_png", datasets.Image())
