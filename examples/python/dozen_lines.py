"""A see-through method in a dozen lines of numpy: the planar crop at d2 -> infinity for a
pinhole frontal camera, from a capture's calibration.json and head.json only.

    python dozen_lines.py INPUTS MAP.npy      then: seethru score INPUTS --map MAP.npy --out scored
"""
import json, sys, numpy as np
inputs, out = sys.argv[1], sys.argv[2]
cal, head = (json.load(open(f"{inputs}/{n}.json")) for n in ("calibration", "head"))
d, f = cal["display"], cal["frontal"]
(w, h), eye = d["resolution_px"], np.array(head["head"]["eye_world_m"])
i, j = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)  # display pixel centres
p = np.stack([(i / w - 0.5) * d["width_m"], (0.5 - j / h) * d["height_m"], 0 * i, 1 + 0 * i], -1)
ray = (p @ np.array(d["world_from_display"]).T)[..., :3] - eye  # d2 -> inf: a direction
c = ray @ np.array(f["world_from_camera"])[:3, :3]  # into OpenCV's camera frame
K = np.array(f["K"])
m = np.stack([K[0, 0] * c[..., 0] / c[..., 2] + K[0, 2], K[1, 1] * c[..., 1] / c[..., 2] + K[1, 2]], -1)
np.save(out, np.where(c[..., 2:] > 0, m, np.nan).astype(np.float32))
json.dump({"capture_fingerprint": json.load(open(f"{inputs}/capture.json"))["fingerprint"]}, open(out + ".json", "w"))
