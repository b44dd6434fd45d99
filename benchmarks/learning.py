"""Speed of the learning protocol, against skrebate's ReliefF measured in the same run.

    python benchmarks/learning.py [--dataset DIR] [--trials 20] [--workers 2]

Times (1) one ReliefF fit on the 1000 x 49 initial features with skrebate and with our vectorised ReliefF,
and (2) the whole protocol of ``affordance reproduce`` (k = 2..10, r in 0..0.8, 20 trials). Without
``--dataset`` it collects 1000 canonical taps first (about 30 s), into a temporary directory.
"""

from __future__ import annotations

import argparse
import tempfile
import time

import numpy as np

from affordance_env.dataset import collect, load_dataset
from affordance_learning.experiment import feature_columns, run_protocol
from affordance_learning.model import AffordanceModel
from affordance_learning.relieff import relieff_weights


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--dataset", default=None)
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()

    path = args.dataset or collect(tempfile.mkdtemp() + "/taps", 1000, seed=0, workers=args.workers)
    frame = load_dataset(path)
    _, initial, effect = feature_columns(frame)
    X, E = frame[initial].to_numpy(np.float64), frame[effect].to_numpy(np.float64)
    labels = AffordanceModel(n_clusters=4, random_state=0).fit(X, E).labels_

    from skrebate import ReliefF

    start = time.perf_counter()
    expected = ReliefF(n_neighbors=10).fit(X, labels).feature_importances_
    skrebate_s = time.perf_counter() - start
    start = time.perf_counter()
    ours = relieff_weights(X, labels, n_neighbors=10)
    ours_s = time.perf_counter() - start
    start = time.perf_counter()
    run_protocol(frame, n_trials=args.trials, n_jobs=args.workers)
    protocol_s = time.perf_counter() - start

    print(f"{len(frame)} interactions x {X.shape[1]} features, 4 effect clusters")
    print(f"  ReliefF, skrebate          : {skrebate_s:8.3f} s")
    print(f"  ReliefF, vectorised        : {ours_s:8.3f} s  ({skrebate_s / ours_s:.0f} x faster; "
          f"max |difference| {np.abs(ours - expected).max():.1e})")
    print(f"  protocol, {args.trials} trials x 9 k x 5 r on {args.workers} workers: {protocol_s:8.1f} s "
          f"(= {protocol_s / skrebate_s:.1f} skrebate ReliefF fits; it runs 180 ReliefF fits)")


if __name__ == "__main__":
    main()
