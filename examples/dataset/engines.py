"""A seethru dataset made on Ray or Dask: one task per shard (`seethru.dataset(..., shard=(k, n))`),
every task writing into one dataset folder (docs/guide/datasets.md).

    python examples/dataset/engines.py ray  examples/dataset/das_pairs.toml das_pairs --shards 2
    python examples/dataset/engines.py dask examples/dataset/das_pairs.toml das_pairs --shards 2

Each task makes its shard with the `seethru` Python package (the wheel: no Rust toolchain and
no binary needed on the workers) with one thread per worker CPU; the task that finishes last
writes the manifest, and a last call without a shard (which finds every sample done) makes
sure of it. The files are the same bytes as one `seethru dataset` process's:
python/tests/test_dataset_engines.py checks both engines against it.
"""

import argparse
import time


def make_shard(spec, out, index, count, threads=1):
    """Makes shard `index` of `count` of the dataset; returns `seethru.dataset`'s summary."""
    import seethru

    return seethru.dataset(spec, out, shard=(index, count), threads=threads)


def finish(spec, out):
    """Writes the manifest if the shards left it unwritten (every sample is kept)."""
    import seethru

    return seethru.dataset(spec, out)


def on_ray(spec, out, shards, num_cpus=2):
    import ray

    ray.init(num_cpus=num_cpus, include_dashboard=False, log_to_driver=False)
    try:
        task = ray.remote(num_cpus=1)(make_shard)
        made = ray.get([task.remote(spec, out, k, shards, 1) for k in range(shards)])
    finally:
        ray.shutdown()
    finish(spec, out)
    return made


def on_dask(spec, out, shards, workers=2):
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with Client(cluster) as client:
            futures = client.map(make_shard, [spec] * shards, [out] * shards, range(shards), [shards] * shards, [1] * shards)
            made = client.gather(futures)
    finish(spec, out)
    return made


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("engine", choices=["ray", "dask"])
    parser.add_argument("spec")
    parser.add_argument("out")
    parser.add_argument("--shards", type=int, default=2)
    parser.add_argument("--workers", type=int, default=2, help="Ray CPUs or Dask worker processes")
    args = parser.parse_args()
    start = time.time()
    run = on_ray if args.engine == "ray" else on_dask
    for k, made in enumerate(run(args.spec, args.out, args.shards, args.workers)):
        print(f"shard {k}/{args.shards}: made {made['made']} samples in {made['seconds']:.1f} s")
    print(f"{args.engine}: {time.time() - start:.1f} s")
