"""Figures of the experiment in the manner of the paper's Figs. 7-11, from :func:`run_protocol` results.

Drawn with matplotlib's object API on the Agg canvas (no pyplot, no display, no global backend setting):

- ``uniformity.png`` (Fig. 7): uniformity against the behaviour's success/fail labels versus k, mean and
  standard deviation, beside what the paper states for the tap or the grasp.
- ``selected_features.png`` (Fig. 8): shares of shape and of size features among the selected ones, and their
  number, versus k, one line per relevancy threshold r.
- ``case_study_k2.png``, ``case_study_k3.png``, ``case_study_k4.png`` (Figs. 9, 10; k = 3 for the grasp): per
  cluster of the 1 x k maps, the success/fail counts (measured by the simulator), the object types and the
  spread of object sizes, with the critical size where success depends on size (the grasp's).
- ``size_success.png`` (not in the paper): the share of successes per object size, with the logistic fit and
  the critical size where it crosses 50 %.
- ``svm_accuracy.png`` (Fig. 11): SVM accuracy on held-out interactions versus k, one line per r, with the
  accuracy of always answering the most common category.
- ``clusters_vs_type.png`` (not in the paper): purity and adjusted Rand index of the clusters against the
  object type versus k.
- ``prototypes.png`` (not in the paper): what each effect category of the 1 x 2 and 1 x 4 maps is, as its
  prototype effect in feature units: the motion of the object's mean point [cm], the change of its pixel count,
  and the change of its normal histograms. A category whose objects mostly left the view has no motion to show
  (its effect is minus the initial features, the not-visible features being zeros): it is marked as such, not
  drawn as centimetres of motion.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.paper.results import Cluster, PerK, PerRK, Results, as_results

_REQUIRED = ("uniformity", "svm_accuracy", "shape_fraction", "size_fraction", "n_selected", "case_studies")
_TYPE_COLOURS = {
    "sphere": "tab:red",
    "horizontal_cylinder": "tab:orange",
    "box": "tab:blue",
    "vertical_cylinder": "tab:cyan",
}
_DPI = 120
#: What the paper states about the mean uniformity over k, per behaviour, and its highest value [%].
_PAPER_UNIFORMITY = {"tap": (80.0, 95.0), "grasp": (70.0, 95.0)}


_Section = TypeVar("_Section")


def _held(section: _Section | None, name: str) -> _Section:
    """A section of the results that :func:`write_figures` made sure they hold (``name`` names it)."""
    if section is None:
        raise InvalidValueError(f"results lack [{name!r}]; expected the results of run_protocol.")
    return section


def _words(results: Results) -> tuple[str, str, str]:
    """The behaviour and how its success and failure read, from the results' config."""
    return results.behavior, results.config.success_label, results.config.fail_label


def _series(per_k: PerK) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """k, mean and std arrays (NaN where a value is None), sorted by k."""
    ks = sorted(per_k)
    mean = np.array([np.nan if per_k[k].mean is None else per_k[k].mean for k in ks], dtype=float)
    std = np.array([np.nan if per_k[k].std is None else per_k[k].std for k in ks], dtype=float)
    return np.array(ks, dtype=int), mean, std


def _new_figure(width: float, height: float, ncols: int = 1, nrows: int = 1) -> tuple[Figure, np.ndarray]:
    fig = Figure(figsize=(width, height), dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    axes = np.atleast_1d(fig.subplots(nrows, ncols))
    return fig, axes.ravel()


def _save(fig: Figure, path: Path) -> Path:
    fig.savefig(path, dpi=_DPI)
    return path


def _uniformity(results: Results, path: Path) -> Path:
    fig, (ax,) = _new_figure(5.5, 3.8)
    behavior, success, fail = _words(results)
    k, mean, std = _series(_held(results.uniformity, "uniformity"))
    ax.errorbar(k, 100.0 * mean, yerr=100.0 * std, marker="o", capsize=3, label="ours (mean ± std over trials)")
    if behavior in _PAPER_UNIFORMITY:
        average, peak = _PAPER_UNIFORMITY[behavior]
        ax.axhline(average, color="grey", linestyle="--", linewidth=1,
                   label=f"paper ({behavior}): above {average:.0f} % on average")
        ax.axhline(peak, color="grey", linestyle=":", linewidth=1, label=f"paper: up to {peak:.0f} %")
    ax.set(
        xlabel="number of clusters k",
        ylabel=f"uniformity vs {success} / {fail} [%]",
        title=f"Uniformity of {behavior} effect clusters (cf. Fig. 7)",
    )
    ax.set_xticks(k)
    ax.set_ylim(0, 102)
    ax.legend(loc="lower right", fontsize="small")
    ax.grid(alpha=0.3)
    return _save(fig, path)


def _per_r(ax: Any, per_rk: PerRK, scale: float = 1.0) -> None:
    for r in sorted(per_rk):
        k, mean, std = _series(per_rk[r])
        ax.errorbar(k, mean * scale, yerr=std * scale, marker="o", markersize=3, capsize=2, label=f"r = {r}")
        ax.set_xticks(k)
    ax.grid(alpha=0.3)


def _selected_features(results: Results, path: Path) -> Path:
    fig, (top, middle, bottom) = _new_figure(6.0, 9.0, nrows=3)
    _per_r(top, _held(results.shape_fraction, "shape_fraction"), 100.0)
    top.set(
        ylabel="shape features [%]", ylim=(0, 102), title="Shape share of the selected features (cf. Fig. 8a)"
    )
    top.legend(fontsize="small", ncols=3)
    _per_r(middle, _held(results.size_fraction, "size_fraction"), 100.0)
    middle.set(ylabel="size features [%]", ylim=(0, 102), title="Size share of the selected features")
    _per_r(bottom, _held(results.n_selected, "n_selected"))
    bottom.set(
        xlabel="number of clusters k",
        ylabel="selected features",
        ylim=(0, None),
        title="Number of selected features (cf. Fig. 8b)",
    )
    return _save(fig, path)


def _case_study(results: Results, k: int, path: Path) -> Path:
    clusters = results.clusters(k)
    behavior, success_label, fail_label = _words(results)
    fig, (ax_label, ax_type, ax_size) = _new_figure(12.0, 3.8, ncols=3)
    index = np.array([c.index for c in clusters])
    success = np.array([c.success for c in clusters])
    fail = np.array([c.fail for c in clusters])
    ax_label.bar(index, success, color="tab:green", label=f"{success_label} (success)")
    ax_label.bar(index, fail, bottom=success, color="tab:gray", label=f"{fail_label} (fail)")
    ax_label.set(xlabel="cluster", ylabel="interactions", title="(a) outcomes measured by the simulator")
    ax_label.legend(fontsize="small")

    types = list(dict.fromkeys(t for c in clusters for t in c.types))
    width = 0.8 / max(len(types), 1)
    for i, t in enumerate(types):
        counts = [c.types.get(t, 0) for c in clusters]
        ax_type.bar(
            index - 0.4 + width * (i + 0.5),
            counts,
            width,
            label=t.replace("_", " "),
            color=_TYPE_COLOURS.get(t),
        )
    ax_type.set(xlabel="cluster", ylabel="interactions", title="(b) object types")
    ax_type.legend(fontsize="small")

    sizes = [np.asarray(c.sizes, dtype=float) * 100.0 for c in clusters]
    filled = [i for i, s in enumerate(sizes) if s.size]
    if filled:
        ax_size.boxplot([sizes[i] for i in filled], positions=index[filled], widths=0.6)
    critical = None if results.size_success is None else results.size_success.critical_size
    if critical is not None:
        ax_size.axhline(100.0 * critical, color="tab:red", linestyle="--", linewidth=1,
                        label=f"critical size {100.0 * critical:.1f} cm")
        ax_size.legend(fontsize="small")
    ax_size.set(xlabel="cluster", ylabel="object size [cm]", title="(c) object sizes")
    for ax in (ax_label, ax_type, ax_size):
        ax.set_xticks(index)
        ax.grid(alpha=0.3, axis="y")
    fig.suptitle(f"{behavior}: 1 x {k} map, first trial (cf. Figs. 9, 10)")
    return _save(fig, path)


def _size_success(results: Results, path: Path) -> Path:
    section = _held(results.size_success, "size_success")
    behavior, success_label, _ = _words(results)
    fig, (ax,) = _new_figure(5.5, 3.8)
    bins = [b for b in section.bins if b.success is not None]
    centres = np.array([50.0 * (b.low + b.high) for b in bins])
    widths = np.array([100.0 * (b.high - b.low) for b in bins])
    ax.bar(centres, [100.0 * (b.success or 0.0) for b in bins], width=0.9 * widths if widths.size else 0.8,
           color="tab:green", alpha=0.5, label="share per size bin")
    if section.logistic is not None and bins:
        fit = section.logistic
        sizes = np.linspace(section.bins[0].low, section.bins[-1].high, 200)
        ax.plot(100.0 * sizes, 100.0 / (1.0 + np.exp(-(fit.intercept + fit.slope * sizes))),
                color="black", label="logistic fit")
    if section.critical_size is not None:
        ax.axvline(100.0 * section.critical_size, color="tab:red", linestyle="--", linewidth=1,
                   label=f"crosses 50 % at {100.0 * section.critical_size:.1f} cm")
    ax.set(xlabel="object size [cm]", ylabel=f"{success_label} [%]", ylim=(0, 102),
           title=f"{behavior}: success by object size")
    ax.legend(fontsize="small")
    ax.grid(alpha=0.3)
    return _save(fig, path)


def _svm_accuracy(results: Results, path: Path) -> Path:
    fig, (ax,) = _new_figure(6.0, 4.0)
    _per_r(ax, _held(results.svm_accuracy, "svm_accuracy"), 100.0)
    if results.svm_baseline is not None:
        k, mean, _ = _series(results.svm_baseline)
        ax.plot(k, mean * 100.0, color="black", linestyle="--", linewidth=1, label="most common category")
    ax.set(
        xlabel="number of clusters k",
        ylabel="accuracy on held-out interactions [%]",
        ylim=(0, 102),
        title="SVM prediction of the effect category (cf. Fig. 11)",
    )
    ax.legend(fontsize="small", ncols=2)
    return _save(fig, path)


def _clusters_vs_type(results: Results, path: Path) -> Path:
    fig, (ax,) = _new_figure(5.5, 3.8)
    for section, label in ((results.purity, "purity"), (results.adjusted_rand, "adjusted Rand index")):
        k, mean, std = _series(_held(section, label))
        ax.errorbar(k, mean, yerr=std, marker="o", capsize=3, label=label)
        ax.set_xticks(k)
    ax.set(xlabel="number of clusters k", ylabel="agreement with object type", ylim=(-0.05, 1.05))
    ax.set_title("Effect clusters against object type (not in the paper)")
    ax.legend(fontsize="small")
    ax.grid(alpha=0.3)
    return _save(fig, path)


#: A category is drawn as "left the view" when more than this share of its objects was not seen at the end.
LEFT_VIEW_SHARE = 0.5


def _prototypes(results: Results, path: Path) -> Path:
    maps = sorted(_held(results.prototypes, "prototypes").items())
    names = list(_held(results.feature_names, "feature_names"))
    _, success, fail = _words(results)
    fig, axes = _new_figure(14.0, 3.2 * len(maps), ncols=4, nrows=len(maps))
    axes = axes.reshape(len(maps), 4)
    index = {n: i for i, n in enumerate(names)}
    lat = [i for i, n in enumerate(names) if n.startswith("normal_lat_")]
    lon = [i for i, n in enumerate(names) if n.startswith("normal_lon_")]
    xyz = [index.get(n) for n in ("mean_x", "mean_y", "mean_z")]
    for row, (k, prototypes) in enumerate(maps):
        P = np.asarray(prototypes, dtype=float)
        clusters = results.clusters(k)
        gone = np.zeros(len(P), dtype=bool)  # categories whose objects mostly left the view
        labels = []
        for c in range(len(P)):
            cl = _cluster(clusters, c)
            if cl is None:
                labels.append(str(c))
                continue
            gone[c] = cl.n > 0 and (cl.left_view or 0) > LEFT_VIEW_SHARE * cl.n
            labels.append(f"{c} ({cl.success} {success} / {cl.fail} {fail})"
                          + (f", {cl.left_view} left the view" if gone[c] else ""))
        ax_move, ax_pix, ax_lat, ax_lon = axes[row]
        if None not in xyz:
            width = 0.8 / 3
            seen = np.flatnonzero(~gone)
            for j, (i, axis) in enumerate(zip(xyz, "xyz", strict=True)):
                ax_move.bar(seen - 0.4 + width * (j + 0.5), 100 * P[seen, i], width, label=f"mean_{axis}")
            for c in np.flatnonzero(gone):  # no motion was seen: the object left the view
                ax_move.axvspan(c - 0.45, c + 0.45, color="0.85", zorder=0)
                ax_move.text(c, 0.5, "object left\nthe view:\nno motion\nseen", ha="center", va="center",
                             fontsize="x-small", transform=ax_move.get_xaxis_transform())
            ax_move.legend(fontsize="x-small")
        ax_move.set(xlabel="cluster", ylabel="change [cm]", title=f"1 x {k}: motion of the mean point")
        if "pixel_count" in index:
            ax_pix.bar(np.arange(len(P)), P[:, index["pixel_count"]],
                       color=["0.8" if g else "tab:gray" for g in gone])
        ax_pix.set(xlabel="cluster", ylabel="change [pixels]", title="pixel count")
        for ax, cols, title in ((ax_lat, lat, "normal latitude histogram"),
                                (ax_lon, lon, "normal longitude histogram")):
            for c in range(len(P)):
                ax.plot(np.arange(len(cols)), P[c, cols], marker=".", label=labels[c],
                        linestyle=":" if gone[c] else "-")
            ax.axhline(0.0, color="grey", linewidth=0.8)
            ax.set(xlabel="bin", ylabel="change [fraction]", title=title)
        ax_lon.legend(fontsize="x-small")
        for ax in (ax_move, ax_pix):
            ax.set_xticks(np.arange(len(P)))
            ax.axhline(0.0, color="grey", linewidth=0.8)
        for ax in axes[row]:
            ax.grid(alpha=0.3)
    fig.suptitle("Prototype effect of each category, in feature units (first trial)")
    return _save(fig, path)


def _cluster(clusters: tuple[Cluster, ...], c: int) -> Cluster | None:
    """The cluster of index ``c``; None when the map does not describe it."""
    return next((cl for cl in clusters if cl.index == c), None)


def write_figures(results: Results | Mapping[str, Any], out_dir: str | Path,
                  progress: bool | None = False) -> list[Path]:
    """Write the figures of the results into ``out_dir`` (created if needed); returns their paths.

    Args:
        results: The :class:`~affordance_learning.paper.results.Results` of
            :func:`affordance_learning.paper.protocol.run_protocol`, or their dict (a ``results.json`` read back).
        out_dir: Directory for the PNG files.
        progress: Draw a progress bar over the figures; None: a bar on a terminal, else a line every 10 s.

    Raises:
        InvalidValueError: The results lack a section the figures need (naming every one), or hold one that is
            not of the format.
    """
    results = as_results(results, required=_REQUIRED)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    drawings = [
        (_uniformity, results, out / "uniformity.png"),
        (_selected_features, results, out / "selected_features.png"),
    ]
    for k in sorted(_held(results.case_studies, "case_studies")):
        drawings.append((lambda r, p, k=k: _case_study(r, k, p), results, out / f"case_study_k{k}.png"))
    drawings.append((_svm_accuracy, results, out / "svm_accuracy.png"))
    if results.size_success is not None:
        drawings.append((_size_success, results, out / "size_success.png"))
    if results.purity is not None and results.adjusted_rand is not None:
        drawings.append((_clusters_vs_type, results, out / "clusters_vs_type.png"))
    if results.prototypes and results.feature_names is not None:
        drawings.append((_prototypes, results, out / "prototypes.png"))
    from affordance_env.progress import progress_bar

    with progress_bar(progress, total=len(drawings), unit="figure", desc="figures") as bar:
        written = []
        for draw, what, path in drawings:
            written.append(draw(what, path))
            bar.update()
    return written
