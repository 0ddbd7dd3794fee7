"""Times `scene.render("truth", width=640, spp=1)` from Python against the same render inside
`seethru bench` (render_into on one reused frame, 1 sample per pixel), median of N repeats.

    python examples/python/bench_render.py [--scene scenes/das.toml] [--repeat 15] [--seethru target/release/seethru]

A benchmark, not a test: on a busy machine run it a few times and read the spread.
"""

import argparse
import json
import statistics
import subprocess
import time

import seethru


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="scenes/das.toml")
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--seethru", default="target/release/seethru")
    args = parser.parse_args()

    scene = seethru.Scene.load(args.scene)
    warm = scene.render("truth", width=args.width, spp=1)  # builds the world once
    height = warm.height
    times = []
    for _ in range(args.repeat):
        start = time.perf_counter()
        scene.render("truth", width=args.width, spp=1)
        times.append((time.perf_counter() - start) * 1e3)
    python_ms = statistics.median(times)

    bench = subprocess.run(
        [args.seethru, "bench", args.scene, "--json", "--width", str(args.width),
         "--height", str(height), "--repeat", str(args.repeat)],
        capture_output=True, text=True, check=True,
    )
    line = json.loads(bench.stdout.strip().splitlines()[-1])
    bench_ms = line["frame"]["truth"]["ms"]
    bench_median = bench_ms["median"] if isinstance(bench_ms, dict) else bench_ms
    print(f"truth {args.width}×{height}, 1 spp, median of {args.repeat}:")
    print(f"  python  {python_ms:8.2f} ms  (min {min(times):.2f}, max {max(times):.2f})")
    print(f"  bench   {bench_median:8.2f} ms  ({bench_ms})")
    print(f"  python / bench = {python_ms / bench_median:.3f}")


if __name__ == "__main__":
    main()
