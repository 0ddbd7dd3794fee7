"""A depth-based compensation in numpy: the captured depth image forward-warped (nearest
neighbour, nearest surface wins) onto the display from the estimated eye; pixels no depth
sample lands on fall back to the planar d2 -> infinity map. Reads calibration.json,
head.json, capture.json and depth.npy (capture with --depth).

    python depth_warp_method.py INPUTS MAP.npy
"""

import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from planar_method import load, planar_map, save  # noqa: E402


def main():
    inputs, path = sys.argv[1], sys.argv[2]
    calibration, head = load(inputs, "calibration.json"), load(inputs, "head.json")
    sensor, frontal, display = (
        calibration["depth_sensor"],
        calibration["frontal"],
        calibration["display"],
    )
    depth = np.load(os.path.join(inputs, "depth.npy"))
    sh, sw = depth.shape
    # Sensor pixels back to world points (the sensor is a pinhole with the frontal pose).
    k = np.array(sensor["K"])
    u, v = np.meshgrid(np.arange(sw, dtype=float), np.arange(sh, dtype=float))
    camera = np.stack(
        [(u - k[0, 2]) / k[0, 0] * depth, (v - k[1, 2]) / k[1, 1] * depth, depth], axis=-1
    )
    world_from_camera = np.array(sensor["world_from_camera"])
    world = camera @ world_from_camera[:3, :3].T + world_from_camera[:3, 3]
    # Into the display frame, and along the ray to the eye onto its plane z = 0.
    display_from_world = np.linalg.inv(np.array(display["world_from_display"]))
    p = world @ display_from_world[:3, :3].T + display_from_world[:3, 3]
    eye = np.array(head["head"]["eye_obstacle_m"])
    t = eye[2] / (eye[2] - p[..., 2])
    hit = eye + (p - eye) * t[..., None]
    w, h = display["resolution_px"]
    i = np.floor((hit[..., 0] / display["width_m"] + 0.5) * w)
    j = np.floor((0.5 - hit[..., 1] / display["height_m"]) * h)
    ok = np.isfinite(depth) & (p[..., 2] < 0) & (i >= 0) & (i < w) & (j >= 0) & (j < h)
    # The sensor pixel's frontal pixel (same pose and field of view, OpenCV centres).
    fw, fh = frontal["image_size"]
    fx, fy = (u + 0.5) * fw / sw - 0.5, (v + 0.5) * fh / sh - 0.5
    distance = np.linalg.norm(p - eye, axis=-1)
    m = planar_map(calibration, head)
    nearest = np.full((h, w), np.inf)
    order = np.argsort(-distance[ok])  # far first: the nearest is written last
    ii, jj = i[ok].astype(int)[order], j[ok].astype(int)[order]
    m[jj, ii, 0], m[jj, ii, 1] = fx[ok][order], fy[ok][order]
    nearest[jj, ii] = distance[ok][order]
    save(inputs, path, m)


if __name__ == "__main__":
    main()
