"""Collection throughput and memory: interactions per second on W workers, RSS of all processes over time.

    python benchmarks/collect.py                                # 1000 interactions, 2 workers (goal <= 30 s)
    python benchmarks/collect.py --episodes 20000 --out /tmp/b  # a long run: does memory stay flat?
    python benchmarks/collect.py --scheduler dask               # the same on a local Dask cluster

Samples the resident memory of this process and all its descendants (the workers) every second while
collecting, and prints the rate and memory for each tenth of the run, so that a long run shows whether memory
stays flat and the rate holds. The dataset goes to a new directory under ``--out`` (default: a temporary one).
"""

from __future__ import annotations

import argparse
import os
import tempfile
import threading
import time
from pathlib import Path


def rss_mib_tree(root: int) -> float:
    """Resident memory of ``root`` and all its descendants [MiB] (Linux /proc)."""
    children: dict[int, list[int]] = {}
    rss: dict[int, int] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            rss[int(entry.name)] = int(fields[21]) * os.sysconf("SC_PAGE_SIZE")
            children.setdefault(int(fields[1]), []).append(int(entry.name))
        except (OSError, IndexError, ValueError):
            continue
    total, stack = 0, [root]
    while stack:
        pid = stack.pop()
        total += rss.get(pid, 0)
        stack.extend(children.get(pid, []))
    return total / 2**20


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=1000, help="interactions (default 1000)")
    parser.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    parser.add_argument("--chunk-size", type=int, default=50)
    parser.add_argument("--scheduler", choices=("joblib", "dask"), default="joblib")
    parser.add_argument("--save-images", action="store_true")
    parser.add_argument("--out", default=None, help="parent of the dataset (default: a temporary directory)")
    args = parser.parse_args()
    out = Path(tempfile.mkdtemp(prefix="collect-bench-", dir=args.out)) / "taps"

    from affordance_env.dataset import collect, read_manifest

    samples: list[tuple[float, float, int]] = []  # (time, RSS of the process tree, chunks written)
    done = threading.Event()

    def sample() -> None:
        while not done.is_set():
            written = sum(1 for _ in out.glob("chunk-*.parquet")) if out.exists() else 0
            samples.append((time.perf_counter(), rss_mib_tree(os.getpid()), written))
            done.wait(1.0)

    thread = threading.Thread(target=sample, daemon=True)
    start = time.perf_counter()
    thread.start()
    collect(out, args.episodes, seed=0, workers=args.workers, chunk_size=args.chunk_size, progress=False,
            scheduler=args.scheduler, save_images=args.save_images)
    elapsed = time.perf_counter() - start
    done.set()
    thread.join()
    manifest = read_manifest(out)
    size = sum(p.stat().st_size for p in out.iterdir()) / 2**20
    failed = manifest["failures"]["count"]
    print(f"{args.episodes} interactions ({manifest['rows']} written, {failed} failed) "
          f"on {args.workers} {args.scheduler} workers in {elapsed:.1f} s: {args.episodes / elapsed:.1f} per "
          f"second; {size:.1f} MiB on disk in {out}")
    print("  time [s]   chunks   interactions/s (since last line)   RSS of all processes [MiB]")
    step = max(1, len(samples) // 10)
    previous = (start, 0)
    for t, rss, chunks in samples[::step]:
        rate = (chunks - previous[1]) * args.chunk_size / max(t - previous[0], 1e-9)
        print(f"  {t - start:8.1f} {chunks:8d} {rate:34.1f} {rss:28.0f}")
        previous = (t, chunks)
    steady = [rss for t, rss, _ in samples if t - start > 0.1 * elapsed]  # after the workers have started
    print(f"  peak RSS {max(s[1] for s in samples):.0f} MiB; after the first tenth of the run: "
          f"min {min(steady, default=0):.0f}, max {max(steady, default=0):.0f} MiB")


if __name__ == "__main__":
    main()
