#!/usr/bin/env python3
"""Open every <view>.exr of a seethru output folder the way users do, and say what each reader finds.

    python3 -m venv /tmp/exr && /tmp/exr/bin/pip install "opencv-python-headless<5" OpenEXR numpy
    /tmp/exr/bin/python tools/check_exr.py out/

OpenCV (IMREAD_UNCHANGED) must return the colour as a float32 image (4 channels, or 3 for the
lean set, which has no A); the OpenEXR
binding must list the AOV layers docs/reference/outputs.md documents (every AOV of `--exr all`,
or the lean set of `run`'s default `--exr lean`). Exits 1 when a reader fails.
"""
import glob
import os
import sys

os.environ.setdefault("OPENCV_IO_ENABLE_OPENEXR", "1")

import cv2  # noqa: E402
import OpenEXR  # noqa: E402

EXPECTED = {"RGBA", "Z", "camera_z.Z", "P.X", "P.Y", "P.Z", "N.X", "N.Y", "N.Z", "id.object", "id.part"}
LEAN = {"RGB", "Z", "N.X", "N.Y", "N.Z", "id.object", "id.part"}


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else "out"
    paths = sorted(glob.glob(os.path.join(folder, "*.exr")))
    if not paths:
        print(f"error: no .exr files in {folder}", file=sys.stderr)
        return 1
    failed = False
    for path in paths:
        image = cv2.imread(path, cv2.IMREAD_UNCHANGED)
        with OpenEXR.File(path) as exr:
            names = set(exr.channels().keys())
        is_view = "Z" in names
        expected = EXPECTED if "P.X" in names or "RGBA" in names else LEAN
        missing = expected - names if is_view else set()
        if image is None or missing:
            failed = True
        shape = "None" if image is None else f"{image.shape} {image.dtype}"
        extra = f"; missing {sorted(missing)}" if missing else ""
        print(f"{os.path.basename(path):24} OpenCV: {shape:24} OpenEXR: {sorted(names)}{extra}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
