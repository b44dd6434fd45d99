"""Collection throughput and memory: interactions per second on W workers, RSS of all processes over time.

    python benchmarks/collect.py [--episodes 1000] [--workers 2] [--out DIR]

Samples the resident memory of this process and its workers every second while collecting, and prints the
rate and memory for each tenth of the run, so that a long run (``--episodes 20000``) shows whether memory
stays flat and the rate does not decay.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import threading
import time
from pathlib import Path


def _rss_mib_tree(root: int) -> float:
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
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=1000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    out = Path(args.out or tempfile.mkdtemp()) / "taps"

    from affordance_env.dataset import collect, load_dataset

    samples: list[tuple[float, float, int]] = []
    done = threading.Event()

    def sample() -> None:
        while not done.is_set():
            written = sum(1 for _ in out.glob("chunk-*.parquet")) if out.exists() else 0
            samples.append((time.perf_counter(), _rss_mib_tree(os.getpid()), written))
            done.wait(1.0)

    thread = threading.Thread(target=sample, daemon=True)
    start = time.perf_counter()
    thread.start()
    collect(out, args.episodes, seed=0, workers=args.workers, chunk_size=50, progress=False)
    elapsed = time.perf_counter() - start
    done.set()
    thread.join()
    frame = load_dataset(out)
    print(f"{len(frame)} interactions on {args.workers} workers in {elapsed:.1f} s: "
          f"{len(frame) / elapsed:.1f} per second")
    print("  time [s]   chunks   interactions/s (since last)   RSS of all processes [MiB]")
    step = max(1, len(samples) // 10)
    previous = (start, 0)
    for t, rss, chunks in samples[::step]:
        rate = (chunks - previous[1]) * 50 / max(t - previous[0], 1e-9)
        print(f"  {t - start:8.1f} {chunks:8d} {rate:29.1f} {rss:28.0f}")
        previous = (t, chunks)
    print(f"  peak RSS {max(s[1] for s in samples):.0f} MiB")


if __name__ == "__main__":
    main()
