"""Sweeps the driver's eye over a grid in the display plane's axes and plots the mean
misregistration of the planar compensation (d2 = inf) at each eye position.

    pip install ./python            # once, from the repository root
    python examples/python/eye_grid_sweep.py [scenes/das.toml] [--width 160] [--steps 5]

Prints one line per eye; with matplotlib installed, also writes eye_grid_sweep.png.
"""

import argparse

import numpy as np

import seethru


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default="scenes/das.toml")
    parser.add_argument("--width", type=int, default=160, help="driver view width, pixels")
    parser.add_argument("--steps", type=int, default=5, help="grid points per axis")
    parser.add_argument("--span", type=float, default=0.10, help="half-width of the grid, metres")
    parser.add_argument("--method", default="planar")
    args = parser.parse_args()

    scene = seethru.Scene.load(args.scene)
    eye0 = np.array(scene.eye)
    # Move the eye in the obstacle frame's x (across the display) and y (up).
    obstacle = scene.obstacle_pose
    across, up = obstacle[:3, 0], obstacle[:3, 1]
    offsets = np.linspace(-args.span, args.span, args.steps)
    mean = np.full((args.steps, args.steps), np.nan)
    for j, dy in enumerate(offsets):
        for i, dx in enumerate(offsets):
            scene.eye = tuple(float(v) for v in eye0 + dx * across + dy * up)
            try:
                result = seethru.run(scene, method=args.method, width=args.width, spp=1, outside="black")
            except ValueError as e:  # an eye the system cannot serve (e.g. behind the display)
                print(f"dx={dx:+.3f} m dy={dy:+.3f} m: {e}")
                continue
            d = result.metrics["display"]["misregistration_arcmin"]
            mean[j, i] = d["mean"] if d["mean"] is not None else np.nan
            print(
                f"dx={dx:+.3f} m dy={dy:+.3f} m: mean misregistration {mean[j, i]:.2f} arcmin "
                f"over {d['count']} of {result.metrics['display_pixels']} display pixels "
                f"({result.metrics['blank_pixels']} blank, {result.metrics['undefined_pixels']} undefined)"
            )
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no plot")
        return
    fig, ax = plt.subplots(figsize=(5, 4))
    extent = [offsets[0] * 100, offsets[-1] * 100, offsets[0] * 100, offsets[-1] * 100]
    image = ax.imshow(mean, origin="lower", extent=extent, cmap="viridis")
    ax.set_xlabel("eye offset across the display, cm")
    ax.set_ylabel("eye offset up, cm")
    ax.set_title(f"mean misregistration, {args.method} (arcmin)")
    fig.colorbar(image, ax=ax, label="arcmin")
    fig.savefig("eye_grid_sweep.png", dpi=120, bbox_inches="tight")
    print("wrote eye_grid_sweep.png")


if __name__ == "__main__":
    main()
