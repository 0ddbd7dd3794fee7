"""Times `scene.render("truth", width=640, spp=1)` from Python against the same render inside
`seethru bench`, in alternating rounds, and prints the median of the rounds' ratios.

    python examples/python/bench_render.py [--scene scenes/das.toml] [--repeat 15] [--rounds 3] [--seethru target/release/seethru]

How it is measured, and what each side includes:
- bench: `seethru bench SCENE --width W --height H --repeat N --json`, whose `frame.truth.ms`
  is the median of N timed `render_into` calls (after one untimed) into one frame reused for
  every repeat, 1 sample per pixel, on the rayon pool's default threads; that is, the
  renderer alone.
- python plain: the median of N calls `f = scene.render("truth", width=W, spp=1)` (after one
  untimed), each timed with `time.perf_counter()` around the call: argument checks, the scene
  copy, the GIL released, the worker thread that keeps Ctrl-C live, the frame (a recycled
  one once an earlier frame has been dropped) and its numpy arrays. `f` is kept until the
  next call has returned, as a loop keeps it.
- python out=: the same, rendering into the frame Python holds (`out=f`).
A round is one bench run then the Python calls; the ratio of each round is python / bench of
the medians. Printed: each round, the median of the rounds' ratios, and the ratio of the
fastest call of all rounds (python's min over bench's min, the figure least disturbed by other
work on a busy machine), with the load average before and after (`os.getloadavg`). For
Python, also the medians per call of the minor page faults (`getrusage`) and of the CPU time of
all the process's threads (`time.process_time`), which a busy machine disturbs far less than
wall time. A benchmark, not a test: on a busy machine read the spread of the rounds.
"""

import argparse
import json
import os
import resource
import statistics
import subprocess
import time

import seethru


COSTS = {}  # per kind of call: [(minor page faults, CPU ms)] of every timed call


def times_ms(repeat, call, kind):
    """(median, min) wall ms of `repeat` timed calls, after one untimed."""
    call()
    times = []
    for _ in range(repeat):
        faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        cpu, start = time.process_time(), time.perf_counter()
        call()
        times.append((time.perf_counter() - start) * 1e3)
        COSTS.setdefault(kind, []).append(
            (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - faults,
             (time.process_time() - cpu) * 1e3))
    return statistics.median(times), min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="scenes/das.toml")
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--seethru", default="target/release/seethru")
    args = parser.parse_args()

    scene = seethru.Scene.load(args.scene)
    held = {"f": scene.render("truth", width=args.width, spp=1)}  # builds the world once
    width, height = held["f"].width, held["f"].height
    has_out = "out" in (seethru.Scene.render.__text_signature__ or "")

    def plain():
        held["f"] = scene.render("truth", width=args.width, spp=1)

    def into():
        scene.render("truth", width=args.width, spp=1, out=held["f"])

    load_before = os.getloadavg()
    rows = []
    for _ in range(args.rounds):
        bench = subprocess.run(
            [args.seethru, "bench", args.scene, "--json", "--width", str(width),
             "--height", str(height), "--repeat", str(args.repeat)],
            capture_output=True, text=True, check=True,
        )
        report = json.loads(bench.stdout.strip().splitlines()[-1])
        ms = report["frame"]["truth"]["ms"]
        row = {"bench": (ms["median"], ms["min"]), "plain": times_ms(args.repeat, plain, "plain")}
        if has_out:
            row["out"] = times_ms(args.repeat, into, "out")
        rows.append(row)
    load_after = os.getloadavg()

    print(f"truth {width}×{height}, 1 spp, {args.rounds} rounds of {args.repeat} repeats "
          f"(bench threads {report['threads']}; load {load_before[0]:.1f} → {load_after[0]:.1f})")
    print("  median (min) ms of each round:")
    for i, row in enumerate(rows):
        cells = "  ".join(f"{k} {v[0]:7.2f} ({v[1]:6.2f})" for k, v in row.items())
        ratios = "  ".join(f"{k}/bench {row[k][0] / row['bench'][0]:.3f}" for k in row if k != "bench")
        print(f"  round {i + 1}: {cells}   {ratios}")
    bench_min = min(row["bench"][1] for row in rows)
    for key in [k for k in rows[0] if k != "bench"]:
        ratios = [row[key][0] / row["bench"][0] for row in rows]
        fastest = min(row[key][1] for row in rows) / bench_min
        print(f"  python {key:<5} / bench: median of rounds {statistics.median(ratios):.3f} "
              f"(rounds {', '.join(f'{r:.3f}' for r in ratios)}); fastest / fastest {fastest:.3f}")
    for kind, costs in COSTS.items():
        print(f"  python {kind:<5} per call: {statistics.median(c[0] for c in costs):.0f} minor page "
              f"faults, {statistics.median(c[1] for c in costs):.2f} ms CPU (all threads)")


if __name__ == "__main__":
    main()
