"""Time the paper's whole learning protocol, and our ReliefF against skrebate's, on a synthetic frame.

Run ``python benchmarks/learning.py [--rows 1000] [--trials 20] [--jobs 2]`` from the repository root (with
the package installed or on ``PYTHONPATH``). No simulator: the frame comes from
:func:`affordance_learning.paper.synthetic.make_synthetic_frame`. Prints, measured in the same run:

- skrebate's ``ReliefF(n_neighbors=10)`` fit on the frame's initial features (rows x 49) against 4 effect
  clusters, and :func:`relieff_weights` on the same data, their ratio and largest difference;
- :func:`run_protocol` (k = 2..10, r in {0, 0.2, 0.4, 0.6, 0.8}, the trials) and its time as a multiple of
  the single skrebate fit. The goal is at most 60 s for 1000 rows x 20 trials on 2 cores.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from sklearn.preprocessing import StandardScaler

from affordance_learning import SOMClustering, relieff_weights, run_protocol
from affordance_learning.common.schema import feature_names
from affordance_learning.paper.synthetic import make_synthetic_frame

GOAL_S = 60.0


def main(argv: list[str] | None = None) -> None:
    """Run the benchmark and print its measurements."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=1000, help="interactions in the synthetic frame")
    parser.add_argument("--trials", type=int, default=20, help="protocol trials")
    parser.add_argument("--jobs", type=int, default=2, help="joblib workers for the protocol")
    args = parser.parse_args(argv)

    from skrebate import ReliefF

    frame = make_synthetic_frame(args.rows, random_state=0)
    names = feature_names(frame)
    X = StandardScaler().fit_transform(frame[[f"initial_{n}" for n in names]].to_numpy())
    E = StandardScaler().fit_transform(frame[[f"effect_{n}" for n in names]].to_numpy())
    labels = SOMClustering(n_clusters=4, random_state=0).fit(E).labels_

    start = time.perf_counter()
    expected = ReliefF(n_neighbors=10).fit(X, labels).feature_importances_
    skrebate_s = time.perf_counter() - start
    relieff_weights(X, labels)  # warm-up
    repeats = 5
    start = time.perf_counter()
    for _ in range(repeats):
        ours = relieff_weights(X, labels)
    ours_s = (time.perf_counter() - start) / repeats
    print(
        f"ReliefF on {X.shape[0]}x{X.shape[1]}, {np.unique(labels).size} classes: "
        f"skrebate {skrebate_s:.2f} s, "
        f"relieff_weights {1e3 * ours_s:.1f} ms ({skrebate_s / ours_s:.0f}x faster), "
        f"largest difference {np.abs(ours - expected).max():.1e}"
    )

    start = time.perf_counter()
    results = run_protocol(frame, n_trials=args.trials, random_state=0, n_jobs=args.jobs)
    protocol_s = time.perf_counter() - start
    n_k, n_r = len(results.config.get("ks")), len(results.config.get("relevancies"))
    print(
        f"run_protocol on {args.rows} rows: {n_k} k x {n_r} r x {args.trials} trials "
        f"({n_k * args.trials} maps and ReliefF weightings, {n_k * n_r * args.trials} SVMs), "
        f"{args.jobs} jobs: {protocol_s:.1f} s "
        f"(goal <= {GOAL_S:.0f} s: {'met' if protocol_s <= GOAL_S else 'MISSED'}), "
        f"{protocol_s / skrebate_s:.1f}x one skrebate ReliefF fit"
    )


if __name__ == "__main__":
    main()
