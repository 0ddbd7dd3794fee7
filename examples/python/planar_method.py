"""The paper's planar compensation, written from scratch in numpy: a display map for
`seethru score`, reading only a capture's calibration.json, head.json and capture.json.

    python planar_method.py INPUTS MAP.npy [--d2 METRES] [--shift K]

For every display pixel, the ray from the estimated eye through the pixel's centre meets
the model plane (d2 -> infinity: the ray's direction); the frontal camera's pixel that sees
that point is the map's entry, in OpenCV's remap convention. --shift K moves the shown image
K display pixels to the right (its first K columns show nothing): a deliberate error.
"""

import argparse
import json
import os

import numpy as np


def load(inputs, name):
    with open(os.path.join(inputs, name)) as f:
        return json.load(f)


def display_points(display):
    """World points of every display pixel's centre, shape (H, W, 3)."""
    w, h = display["resolution_px"]
    i, j = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    obstacle = np.stack(
        [
            (i / w - 0.5) * display["width_m"],
            (0.5 - j / h) * display["height_m"],
            np.zeros_like(i),
            np.ones_like(i),
        ],
        axis=-1,
    )
    return (obstacle @ np.array(display["world_from_display"]).T)[..., :3]


def project(camera, points, directions=False):
    """OpenCV pixels of world points (or directions) seen by a calibrated camera."""
    world_from_camera = np.array(camera["world_from_camera"])
    r = world_from_camera[:3, :3].T
    t = -r @ world_from_camera[:3, 3]
    c = points @ r.T + (0.0 if directions else t)
    a, b = c[..., 0] / c[..., 2], c[..., 1] / c[..., 2]
    model, k = camera["distortion_model"], camera["distortion_coefficients"]
    if model == "opencv":
        k1, k2, p1, p2, k3 = k
        r2 = a * a + b * b
        radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
        a, b = (
            a * radial + 2 * p1 * a * b + p2 * (r2 + 2 * a * a),
            b * radial + p1 * (r2 + 2 * b * b) + 2 * p2 * a * b,
        )
    elif model != "pinhole":
        raise SystemExit(f"error: distortion model {model} is not implemented here")
    kk = np.array(camera["K"])
    x = kk[0, 0] * a + kk[0, 1] * b + kk[0, 2]
    y = kk[1, 1] * b + kk[1, 2]
    behind = c[..., 2] <= 0
    return np.where(behind, np.nan, x), np.where(behind, np.nan, y)


def planar_map(calibration, head, d2=None):
    display = calibration["display"]
    eye = np.array(head["head"]["eye_world_m"])
    p = display_points(display)
    if d2 is None:
        x, y = project(calibration["frontal"], p - eye, directions=True)
    else:
        # The ray eye -> pixel, continued to the plane d2 behind the display.
        normal = np.array(display["normal_world"])
        d1 = (eye - p[0, 0]) @ normal
        x, y = project(calibration["frontal"], eye + (p - eye) * (d1 + d2) / d1)
    return np.stack([x, y], axis=-1).astype(np.float32)


def shifted(m, k):
    """The map moved k display pixels to the right; the uncovered columns show nothing."""
    out = np.full_like(m, np.nan)
    if k > 0:
        out[:, k:] = m[:, :-k]
    elif k < 0:
        out[:, :k] = m[:, -k:]
    else:
        out[:] = m
    return out


def save(inputs, path, m):
    np.save(path, m)
    with open(path + ".json", "w") as f:
        json.dump({"capture_fingerprint": load(inputs, "capture.json")["fingerprint"]}, f)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("inputs")
    parser.add_argument("map")
    parser.add_argument("--d2", type=float, default=None)
    parser.add_argument("--shift", type=int, default=0)
    args = parser.parse_args()
    m = planar_map(load(args.inputs, "calibration.json"), load(args.inputs, "head.json"), args.d2)
    save(args.inputs, args.map, shifted(m, args.shift))


if __name__ == "__main__":
    main()
