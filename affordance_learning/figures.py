"""Figures in the manner of the paper's Figs. 7-11, drawn from a results dict of :func:`run_protocol`."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: files only
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

TYPE_ORDER = ("sphere", "horizontal_cylinder", "box", "vertical_cylinder")


def _ks(per_k: dict) -> list[int]:
    return sorted(int(k) for k in per_k)


def _series(per_k: dict) -> tuple[list[int], np.ndarray, np.ndarray]:
    ks = _ks(per_k)
    return ks, np.array([per_k[str(k)]["mean"] for k in ks]), np.array([per_k[str(k)]["std"] for k in ks])


def uniformity_figure(results: dict, path: Path) -> Path:
    """Fig. 7: uniformity of the effect clusters against rolled / not rolled, versus k."""
    ks, mean, std = _series(results["uniformity"])
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.errorbar(ks, mean, yerr=std, marker="o", capsize=3, label="tap (this reproduction)")
    ax.axhline(80, color="grey", ls="--", lw=1, label="paper: above 80 % on average")
    ax.set(xlabel="number of clusters k", ylabel="uniformity [%]", ylim=(0, 105), title="Uniformity of effect clusters")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def selected_features_figure(results: dict, path: Path) -> Path:
    """Fig. 8: share of shape features among the selected ones, and their number, versus k for each r."""
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(5.5, 6), sharex=True)
    for r in sorted(results["shape_fraction"], key=float):
        ks, share, _ = _series(results["shape_fraction"][r])
        top.plot(ks, 100 * share, marker="o", label=f"r = {r}")
        ks, count, std = _series(results["n_selected"][r])
        bottom.errorbar(ks, count, yerr=std, marker="o", capsize=2, label=f"r = {r}")
    top.axhline(100 * 24 / 49, color="grey", ls=":", lw=1, label="all 49 features")
    top.set(ylabel="shape features [%]", ylim=(0, 105), title="Selected features")
    bottom.set(xlabel="number of clusters k", ylabel="number selected")
    top.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def case_study_figure(results: dict, k: str, path: Path) -> Path:
    """Figs. 9-10: per cluster of a 1 x k map, rolled / not rolled, object types and sizes."""
    clusters = results["case_studies"][k]
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6))
    idx = np.arange(len(clusters))
    rolled = [c["rolled"] for c in clusters]
    not_rolled = [c["not_rolled"] for c in clusters]
    axes[0].bar(idx - 0.2, rolled, 0.4, label="rolled")
    axes[0].bar(idx + 0.2, not_rolled, 0.4, label="not rolled")
    axes[0].set(xlabel="cluster", ylabel="interactions", title="Rolled / not rolled")
    axes[0].legend(fontsize=8)
    bottom = np.zeros(len(clusters))
    types = [t for t in TYPE_ORDER if any(t in c["types"] for c in clusters)]
    types += sorted({t for c in clusters for t in c["types"]} - set(types))
    for t in types:
        counts = np.array([c["types"].get(t, 0) for c in clusters])
        axes[1].bar(idx, counts, bottom=bottom, label=t.replace("_", " "))
        bottom += counts
    axes[1].set(xlabel="cluster", title="Object types")
    axes[1].legend(fontsize=7)
    sizes = [np.array(c["sizes"]) * 100 for c in clusters]
    axes[2].boxplot([s if len(s) else [np.nan] for s in sizes], positions=idx)
    axes[2].set(xlabel="cluster", ylabel="object size [cm]", title="Sizes")
    for ax in axes:
        ax.set_xticks(idx)
    fig.suptitle(f"Case study: 1 x {k} map")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def svm_accuracy_figure(results: dict, path: Path) -> Path:
    """Fig. 11: accuracy of the SVM predicting the effect cluster, versus k for each r."""
    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    for r in sorted(results["svm_accuracy"], key=float):
        ks, mean, std = _series(results["svm_accuracy"][r])
        ax.errorbar(ks, 100 * mean, yerr=100 * std, marker="o", capsize=2, label=f"r = {r}")
    if "svm_majority_baseline" in results:
        ks, base, _ = _series(results["svm_majority_baseline"])
        ax.plot(ks, 100 * base, color="grey", ls="--", lw=1, label="most common cluster")
    ax.set(xlabel="number of clusters k", ylabel="test accuracy [%]", ylim=(0, 102), title="Effect prediction (SVM)")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def write_figures(results: dict, out_dir) -> list[Path]:
    """Write every figure as PNG into ``out_dir``; returns their paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = [
        uniformity_figure(results, out / "uniformity.png"),
        selected_features_figure(results, out / "selected_features.png"),
    ]
    for k in sorted(results.get("case_studies", {}), key=int):
        paths.append(case_study_figure(results, k, out / f"case_study_k{k}.png"))
    paths.append(svm_accuracy_figure(results, out / "svm_accuracy.png"))
    return paths
