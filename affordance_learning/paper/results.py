"""The results of :func:`~affordance_learning.paper.protocol.run_protocol`: their format and units, the reading of older
ones, and :class:`Results`, the typed, read-only view every report, figure and check reads them through.

Units (:data:`UNITS`, also written into every results dict as ``config["units"]``): every share is a fraction
in [0, 1] (uniformity, SVM accuracy and its baseline, the shape and size shares of the selected features, the
share of successes, purity); sizes and distances are in metres, times in seconds. Reports and figures show
shares as percentages.

The results dict (and its ``results.json``) keys a map size k by :func:`k_key` (``str(k)``: "2", "3", ...) and a
relevancy threshold r by :func:`r_key` (``str(float(r))``: "0.0", "0.2", ...); :class:`Results` keys them by
number, so that no reader handles those strings.

Format 1 (written before ``results_format`` existed) gave the uniformity in percent; :func:`current_results`
reads it as format 2, so reports, figures and claims can be drawn from an ``results.json`` of either.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Iterable, Iterator, Mapping, MutableMapping
from dataclasses import dataclass, field, fields
from types import MappingProxyType
from typing import Any

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.json_reading import Path as _Path
from affordance_learning.common.json_reading import Reader, is_number

#: Version of the results dict; raise it when the meaning or the unit of a key changes.
RESULTS_FORMAT = 2
UNITS = ("shares (uniformity, SVM accuracy and baseline, feature shares, success shares, purity) are fractions "
         "in [0, 1]; sizes and distances in metres; times in seconds")
#: How the paper defines uniformity, for each report to say.
UNIFORMITY_DEFINITION = (
    "Uniformity (the paper's measure of how well the effect clusters agree with the success/fail labels): "
    "U = sum over clusters c of |S_c - F_c| / T, with S_c and F_c the successes and failures in cluster c and T "
    "all interactions; 100 % when every cluster holds only successes or only failures, 0 % when each holds "
    "as many of both."
)
#: What the error messages point to.
_EXPECTED = "expected the dict returned by run_protocol"

_READ = Reader("results", _EXPECTED)
_where, _mapping, _list, _entry = _READ.where, _READ.mapping, _READ.list, _READ.entry
_number, _count, _is_number = _READ.number, _READ.count, is_number


def k_key(k: int) -> str:
    """The key of map size ``k`` (a number of clusters) in a results dict: ``str(k)``, "2" for 2."""
    return str(int(k))


def r_key(r: float) -> str:
    """The key of relevancy threshold ``r`` (a fraction of the largest ReliefF weight) in a results dict:
    ``str(float(r))``, "0.4" for 0.4 and "0.0" for 0."""
    return str(float(r))


def current_results(results: Mapping[str, Any]) -> Mapping[str, Any]:
    """``results`` in the current format: format 1 (no ``results_format``, uniformity in percent) is read as
    format 2 (a fraction) in a copy; a current one is returned as it is. A newer one raises InvalidValueError."""
    found = results.get("results_format", 1)
    if found == RESULTS_FORMAT:
        return results
    if found != 1:
        raise InvalidValueError(
            f"results of format {found!r}; this tap-affordance reads formats 1 to {RESULTS_FORMAT}: "
                         "upgrade the package.")
    upgraded = copy.deepcopy(dict(results))
    uniformity = upgraded.get("uniformity")
    for entry in (uniformity.values() if isinstance(uniformity, Mapping) else ()):
        for key in ("mean", "std"):
            if isinstance(entry, MutableMapping) and entry.get(key) is not None:
                entry[key] = entry[key] / 100.0
    upgraded["results_format"] = RESULTS_FORMAT
    return upgraded


# --- the parts ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Stat:
    """One number over the trials of the protocol, in the unit of its section (a share as a fraction in [0, 1], a
    count as a count).

    Attributes:
        mean: The mean over the trials; None when no trial gave a finite value.
        std: The population standard deviation (ddof = 0) over the trials; None with the mean.
    """

    mean: float | None
    std: float | None

    def to_dict(self) -> dict[str, float | None]:
        """``{"mean", "std"}``, as the results dict holds it."""
        return {"mean": self.mean, "std": self.std}


#: A number per map size k (k -> :class:`Stat`), read-only, in the order the results hold it.
PerK = Mapping[int, Stat]
#: A number per relevancy threshold r and map size k (r -> k -> :class:`Stat`), read-only, in the order held.
PerRK = Mapping[float, PerK]
_NO_STATS: PerK = MappingProxyType({})


@dataclass(frozen=True)
class Cluster:
    """One node of a 1 x k map of the first trial (``case_studies``).

    Attributes:
        index: The node's index, 0 to k - 1 (``"cluster"``).
        success: How many of its interactions succeeded.
        fail: How many failed.
        types: How many of its interactions had each object type, in the order held.
        sizes: The sizes of its objects [m], sorted.
        left_view: How many of its objects were not seen in the final snapshot; None in results of format 1,
            which did not count them.
    """

    index: int
    success: int
    fail: int
    types: Mapping[str, int]
    sizes: tuple[float, ...] = field(repr=False)
    left_view: int | None = None

    @property
    def n(self) -> int:
        """The interactions in the cluster."""
        return self.success + self.fail

    def to_dict(self) -> dict[str, Any]:
        """The cluster as the results dict holds it."""
        out = {"cluster": self.index, "success": self.success, "fail": self.fail, "types": dict(self.types),
               "sizes": list(self.sizes)}
        return out if self.left_view is None else {**out, "left_view": self.left_view}


@dataclass(frozen=True)
class SizeBin:
    """One bin of object sizes: its bounds [m], its interactions and their share of successes (None when empty)."""

    low: float
    high: float
    n: int
    success: float | None


@dataclass(frozen=True)
class Logistic:
    """The logistic fit of success on object size: P(success) = 1 / (1 + exp(-(intercept + slope x size))), size
    in metres (``slope`` in 1/m)."""

    intercept: float
    slope: float


@dataclass(frozen=True)
class SizeTest:
    """Whether success depends on size: the likelihood-ratio test's p-value, the fitted share's change across the
    sizes seen (``span``, a fraction, at the largest size minus at the smallest), the verdict and its rule."""

    p_value: float
    span: float
    depends_on_size: bool
    rule: str


@dataclass(frozen=True)
class SizeSide:
    """The interactions on one side of the critical size (``below``: smaller objects, ``above``: the others) and
    their share of successes (None when there are none)."""

    n: int
    success: float | None


@dataclass(frozen=True)
class SizeSuccess:
    """How success depends on object size (:func:`affordance_learning.paper.metrics.size_success`).

    Attributes:
        bins: The share of successes per size bin.
        logistic: The fit of success on size; None with only one outcome.
        test: Whether success depends on size; None without a fit (or in results written before the test).
        critical_size: Where the fit crosses 50 % [m]; None when success does not depend on size or the fit does
            not cross 50 % within the sizes seen.
        below: The interactions with objects smaller than the critical size; None without one.
        above: Those with objects not smaller; None without one.
    """

    bins: tuple[SizeBin, ...]
    logistic: Logistic | None = None
    test: SizeTest | None = None
    critical_size: float | None = None
    below: SizeSide | None = None
    above: SizeSide | None = None

    @property
    def critical_split(self) -> tuple[float, float, float] | None:
        """The critical size [m] and the shares of successes (fractions) below and above it; None without a
        critical size, or with no object on one side of it."""
        if self.critical_size is None or self.below is None or self.above is None:
            return None
        if self.below.success is None or self.above.success is None:
            return None
        return self.critical_size, self.below.success, self.above.success

    def to_dict(self) -> dict[str, Any]:
        """The section as the results dict holds it."""
        def plain(part: Any) -> Any:
            return None if part is None else {f.name: getattr(part, f.name) for f in fields(part)}

        return {"bins": [plain(b) for b in self.bins], "logistic": plain(self.logistic), "test": plain(self.test),
                "critical_size": self.critical_size, "below": plain(self.below), "above": plain(self.above)}


@dataclass(frozen=True)
class TypeEffects:
    """What the effects of one object type contain (:func:`affordance_learning.paper.diagnostics.effect_summary`): its
    interactions; the shares (fractions) of successes, of objects at rest, seen in the final snapshot and off the
    table; the medians of the travel [m], of the 3-D motion seen [m], of the change of the pixel count [pixels] and
    of the normal histograms (sum of |effect| over the shape features). None where the dataset could not say."""

    n: int
    success: float | None
    rest: float | None
    visible_final: float | None
    off_table: float | None
    displacement: float | None
    seen_motion: float | None
    pixel_count_change: float | None
    shape_change: float | None


@dataclass(frozen=True)
class Effects:
    """What the effects contain (``effects``): per object type, and over all successes the shares (fractions)
    seen at the end (at rest and seen), whose effect is minus their initial features, and the Spearman correlation
    of the travel with the motion seen. None where the dataset could not say."""

    by_type: Mapping[str, TypeEffects]
    success_visible: float | None = None
    success_rest_visible: float | None = None
    success_effect_is_minus_initial: float | None = None
    travel_vs_seen_motion: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """The section as the results dict holds it."""
        by_type = {t: {f.name: getattr(row, f.name) for f in fields(row)} for t, row in self.by_type.items()}
        return {"by_type": by_type, **{f.name: getattr(self, f.name) for f in fields(self) if f.name != "by_type"}}


@dataclass(frozen=True)
class Config:
    """The settings a results dict records (``config``): read through the typed properties what is computed on,
    and through :meth:`get` and :meth:`items` anything else, as written (the protocol's and ``affordance
    reproduce``'s settings, for the reports to list)."""

    entries: Mapping[str, Any]

    def get(self, key: str, default: Any = None) -> Any:
        """The setting ``key`` as written (a copy: the results stay as they were read), or ``default``."""
        return copy.deepcopy(self.entries.get(key, default))

    def items(self) -> Iterator[tuple[str, Any]]:
        """Every setting as written, in the order held (copies)."""
        return ((key, copy.deepcopy(value)) for key, value in self.entries.items())

    @property
    def behavior(self) -> str:
        """The behaviour of the interactions; results without it, written before it was recorded, are the tap's."""
        return str(self.entries.get("behavior", "tap"))

    @property
    def success_label(self) -> str:
        """How a success reads ("rolled", "lifted and held"; "success" when the results do not say)."""
        return self.entries.get("success_label", "success")

    @property
    def fail_label(self) -> str:
        """How a failure reads ("did not roll", ...; "fail" when the results do not say)."""
        return self.entries.get("fail_label", "fail")

    @property
    def n_trials(self) -> int | None:
        """The protocol's trials; None when the results do not say."""
        return _count_or_none(self.entries.get("n_trials"))

    @property
    def n_rows(self) -> int | None:
        """The interactions the protocol ran on; None when the results do not say."""
        return _count_or_none(self.entries.get("n_rows"))

    @property
    def success_fraction(self) -> float | None:
        """The share of successes among the interactions, a fraction in [0, 1]; None when the results do not
        say."""
        value: Any = self.entries.get("success_fraction")
        return float(value) if _is_number(value) else None


# --- the results ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Results:
    """The results of :func:`~affordance_learning.paper.protocol.run_protocol` (or of its ``results.json``), typed and
    read-only, in the current format: build it with :meth:`from_dict`.

    Every section is None when the results lack it (results may be partial: the claims on what they hold are
    still judged). Map sizes k are ints, relevancy thresholds r floats; each mapping keeps the order the results
    hold. Shares are fractions in [0, 1] (:data:`UNITS`).

    Attributes:
        results_format: The format read (:data:`RESULTS_FORMAT`; format 1 is upgraded).
        config: The recorded settings.
        uniformity: Uniformity of the clusters against the success/fail labels, per k [fraction].
        purity: Purity of the clusters against the object type, per k [fraction].
        adjusted_rand: Adjusted Rand index of the clusters against the object type, per k.
        n_categories: Non-empty clusters, per k.
        svm_baseline: Accuracy of always answering the most common training category, per k [fraction].
        svm_accuracy: SVM accuracy on held-out interactions, per r and k [fraction].
        shape_fraction: Share of shape features among the selected ones, per r and k [fraction].
        size_fraction: Share of size features among the selected ones, per r and k [fraction].
        n_selected: Number of selected features, per r and k.
        case_studies: The clusters of the 1 x k maps of the first trial, per k.
        prototypes: The prototype effect of each node of those maps, per k, in feature units (one row per node,
            one value per feature of :attr:`feature_names`).
        feature_names: The names of the features.
        feature_weights: The mean ReliefF weight of each feature, per k.
        effects: What the effects contain.
        size_success: How success depends on object size.
    """

    results_format: int
    config: Config
    uniformity: PerK | None = None
    purity: PerK | None = None
    adjusted_rand: PerK | None = None
    n_categories: PerK | None = None
    svm_baseline: PerK | None = None
    svm_accuracy: PerRK | None = None
    shape_fraction: PerRK | None = None
    size_fraction: PerRK | None = None
    n_selected: PerRK | None = None
    case_studies: Mapping[int, tuple[Cluster, ...]] | None = None
    prototypes: Mapping[int, tuple[tuple[float, ...], ...]] | None = None
    feature_names: tuple[str, ...] | None = None
    feature_weights: Mapping[int, Mapping[str, float]] | None = None
    effects: Effects | None = None
    size_success: SizeSuccess | None = None

    @classmethod
    def from_dict(cls, results: Results | Mapping[str, Any], required: Iterable[str] = ()) -> Results:
        """Read a results dict (of any format this package reads, :func:`current_results`) and check it.

        Args:
            results: The dict of :func:`~affordance_learning.paper.protocol.run_protocol`, or its ``results.json`` read
                back, or part of it.
            required: Sections the caller cannot do without (``"uniformity"``, ``"case_studies"``, ...).

        Raises:
            InvalidValueError: ``results`` is not a mapping, is of a newer format, lacks a ``required`` section
                (naming every one it lacks), or holds a section that is not of the format (naming where: a key
                that is no k or r, an entry without its ``mean``, a cluster without its counts, ...).
        """
        if isinstance(results, Results):
            results.check_required(required)
            return results
        if not isinstance(results, Mapping):
            raise InvalidValueError(f"results must be a mapping, {_EXPECTED} (or its results.json read back), "
                                    f"got {type(results).__name__}.")
        current = current_results(results)
        parsed = cls(
            results_format=RESULTS_FORMAT,
            config=Config(MappingProxyType(copy.deepcopy(dict(_mapping(current.get("config") or {}, ("config",)))))),
            **{name: _optional(current, name, _per_k) for name in _PER_K},
            **{name: _optional(current, name, _per_rk) for name in _PER_RK},
            case_studies=_optional(current, "case_studies", _case_studies),
            prototypes=_optional(current, "prototypes", _prototypes),
            feature_names=_optional(current, "feature_names", _feature_names),
            feature_weights=_optional(current, "feature_weights", _feature_weights),
            effects=_optional(current, "effects", _effects),
            size_success=_optional(current, "size_success", _size_success),
        )
        parsed.check_required(required)
        return parsed

    def missing(self, sections: Iterable[str]) -> list[str]:
        """Which of ``sections`` (names of the results dict: ``"uniformity"``, ``"svm_accuracy"``, ...) the results
        lack, in the order given."""
        unknown = [name for name in sections if name not in _SECTIONS]
        if unknown:
            raise InvalidValueError(f"no results section {unknown[0]!r}; the sections are {', '.join(_SECTIONS)}.")
        return [name for name in sections if getattr(self, name) is None]

    def check_required(self, sections: Iterable[str]) -> None:
        """Raise InvalidValueError naming the ``sections`` the results lack, if any."""
        missing = self.missing(list(sections))
        if missing:
            raise InvalidValueError(f"results lack {missing}; {_EXPECTED}.")

    # --- queries ---
    @property
    def behavior(self) -> str:
        """The behaviour of the interactions (``config["behavior"]``; the tap's when the results do not say)."""
        return self.config.behavior

    @property
    def success_share(self) -> float | None:
        """The share of successes among the interactions, a fraction in [0, 1]; None when the results do not
        say."""
        return self.config.success_fraction

    @property
    def ks(self) -> tuple[int, ...]:
        """The map sizes k of the uniformity, ascending."""
        return tuple(sorted(self.uniformity or ()))

    @property
    def rs(self) -> tuple[float, ...]:
        """The relevancy thresholds r of the SVM accuracy, ascending."""
        return tuple(sorted(self.svm_accuracy or ()))

    def accuracy(self, r: float) -> PerK:
        """SVM accuracy on held-out interactions per k at relevancy ``r`` [fraction]; empty when r was not run."""
        return (self.svm_accuracy or {}).get(float(r), _NO_STATS)

    def clusters(self, k: int) -> tuple[Cluster, ...]:
        """The clusters of the 1 x ``k`` map of the first trial; empty when it was not described."""
        return (self.case_studies or {}).get(int(k), ())

    def to_dict(self) -> dict[str, Any]:
        """The results dict of the current format, as :func:`~affordance_learning.paper.protocol.run_protocol` writes
        it (the sections held, with k and r keyed by :func:`k_key` and :func:`r_key`)."""
        out: dict[str, Any] = {"results_format": self.results_format}
        for name in _PER_K:
            if (section := getattr(self, name)) is not None:
                out[name] = {k_key(k): s.to_dict() for k, s in section.items()}
        for name in _PER_RK:
            if (section := getattr(self, name)) is not None:
                out[name] = {r_key(r): {k_key(k): s.to_dict() for k, s in per_k.items()}
                             for r, per_k in section.items()}
        if self.case_studies is not None:
            out["case_studies"] = {k_key(k): [c.to_dict() for c in cs] for k, cs in self.case_studies.items()}
        if self.prototypes is not None:
            out["prototypes"] = {k_key(k): [list(row) for row in p] for k, p in self.prototypes.items()}
        if self.feature_names is not None:
            out["feature_names"] = list(self.feature_names)
        if self.feature_weights is not None:
            out["feature_weights"] = {k_key(k): dict(w) for k, w in self.feature_weights.items()}
        if self.effects is not None:
            out["effects"] = self.effects.to_dict()
        if self.size_success is not None:
            out["size_success"] = self.size_success.to_dict()
        out["config"] = dict(self.config.items())
        return out


#: The sections of a results dict, per k and per r and k, and all of them, as :class:`Results` names them.
_PER_K = ("uniformity", "purity", "adjusted_rand", "n_categories", "svm_baseline")
_PER_RK = ("svm_accuracy", "shape_fraction", "size_fraction", "n_selected")
_SECTIONS = (*_PER_K, *_PER_RK, "case_studies", "prototypes", "feature_names", "feature_weights", "effects",
             "size_success")


def as_results(results: Results | Mapping[str, Any], required: Iterable[str] = ()) -> Results:
    """``results`` as :class:`Results` (read with :meth:`Results.from_dict` unless it is one), with the
    ``required`` sections."""
    return Results.from_dict(results, required)


# --- reading and checking -------------------------------------------------------------------------------------


def _count_or_none(value: Any) -> int | None:
    return int(value) if _is_number(value) else None


def _k(key: Any, path: _Path) -> int:
    try:
        return int(key)
    except (TypeError, ValueError):
        raise InvalidValueError(f"{_where(path)} holds the key {key!r}, which is not a map size k (an integer "
                                f"written as str(k)); {_EXPECTED}.") from None


def _r(key: Any, path: _Path) -> float:
    try:
        return float(key)
    except (TypeError, ValueError):
        raise InvalidValueError(f"{_where(path)} holds the key {key!r}, which is not a relevancy threshold r (a "
                                f"number written as str(float(r))); {_EXPECTED}.") from None


def _optional(results: Mapping[str, Any], name: str, read: Callable[[Any, _Path], Any]) -> Any:
    """Section ``name`` read by ``read``; None when the results lack it (or hold None)."""
    value = results.get(name)
    return None if value is None else read(value, (name,))


def _stat(value: Any, path: _Path) -> Stat:
    entry = _entry(value, path, ("mean", "std"))
    return Stat(_number(entry["mean"], (*path, "mean"), True), _number(entry["std"], (*path, "std"), True))


def _per_k(value: Any, path: _Path) -> PerK:
    section = _mapping(value, path)
    return MappingProxyType({_k(k, path): _stat(entry, (*path, k)) for k, entry in section.items()})


def _per_rk(value: Any, path: _Path) -> PerRK:
    section = _mapping(value, path)
    return MappingProxyType({_r(r, path): _per_k(per_k, (*path, r)) for r, per_k in section.items()})


def _cluster(value: Any, path: _Path) -> Cluster:
    entry = _entry(value, path, ("cluster", "success", "fail", "types", "sizes"))
    types = _mapping(entry["types"], (*path, "types"))
    return Cluster(
        index=_count(entry["cluster"], (*path, "cluster")),
        success=_count(entry["success"], (*path, "success")),
        fail=_count(entry["fail"], (*path, "fail")),
        types=MappingProxyType({str(t): _count(n, (*path, "types", t)) for t, n in types.items()}),
        sizes=tuple(_number(s, (*path, "sizes")) for s in _list(entry["sizes"], (*path, "sizes"))),
        left_view=None if entry.get("left_view") is None else _count(entry["left_view"], (*path, "left_view")),
    )


def _case_studies(value: Any, path: _Path) -> Mapping[int, tuple[Cluster, ...]]:
    section = _mapping(value, path)
    return MappingProxyType({
        _k(k, path): tuple(_cluster(c, (*path, k, i)) for i, c in enumerate(_list(cs, (*path, k))))
        for k, cs in section.items()})


def _prototypes(value: Any, path: _Path) -> Mapping[int, tuple[tuple[float, ...], ...]]:
    section = _mapping(value, path)
    return MappingProxyType({
        _k(k, path): tuple(tuple(_number(v, (*path, k)) for v in _list(row, (*path, k)))
                           for row in _list(rows, (*path, k)))
        for k, rows in section.items()})


def _feature_names(value: Any, path: _Path) -> tuple[str, ...]:
    return tuple(str(name) for name in _list(value, path))


def _feature_weights(value: Any, path: _Path) -> Mapping[int, Mapping[str, float]]:
    section = _mapping(value, path)
    return MappingProxyType({
        _k(k, path): MappingProxyType({str(n): _number(w, (*path, k, n))
                                       for n, w in _mapping(weights, (*path, k)).items()})
        for k, weights in section.items()})


def _effects(value: Any, path: _Path) -> Effects:
    section = _mapping(value, path)
    shares = [f.name for f in fields(TypeEffects) if f.name != "n"]
    by_type = {}
    for t, row in _mapping(section.get("by_type") or {}, (*path, "by_type")).items():
        where = (*path, "by_type", t)
        entry = _entry(row, where, ("n", *shares))
        by_type[str(t)] = TypeEffects(n=_count(entry["n"], (*where, "n")),
                                      **{s: _number(entry[s], (*where, s), True) for s in shares})
    overall = [f.name for f in fields(Effects) if f.name != "by_type"]
    return Effects(by_type=MappingProxyType(by_type),
                   **{s: _number(section.get(s), (*path, s), True) for s in overall})


def _size_success(value: Any, path: _Path) -> SizeSuccess:
    section = _entry(value, path, ("bins",))
    bins = []
    for i, b in enumerate(_list(section["bins"], (*path, "bins"))):
        where = (*path, "bins", i)
        entry = _entry(b, where, ("low", "high", "n", "success"))
        bins.append(SizeBin(_number(entry["low"], (*where, "low")), _number(entry["high"], (*where, "high")),
                            _count(entry["n"], (*where, "n")), _number(entry["success"], (*where, "success"),
                                                                         True)))

    def part(key: str, keys: tuple[str, ...]) -> Mapping[str, Any] | None:
        return None if section.get(key) is None else _entry(section[key], (*path, key), keys)

    fit, test = part("logistic", ("intercept", "slope")), part("test", ("p_value", "span", "depends_on_size", "rule"))
    sides = {key: part(key, ("n", "success")) for key in ("below", "above")}
    return SizeSuccess(
        bins=tuple(bins),
        logistic=None if fit is None else Logistic(_number(fit["intercept"], (*path, "logistic", "intercept")),
                                                   _number(fit["slope"], (*path, "logistic", "slope"))),
        test=None if test is None else SizeTest(_number(test["p_value"], (*path, "test", "p_value")),
                                                _number(test["span"], (*path, "test", "span")),
                                                bool(test["depends_on_size"]), str(test["rule"])),
        critical_size=_number(section.get("critical_size"), (*path, "critical_size"), True),
        **{key: None if side is None else SizeSide(_count(side["n"], (*path, key, "n")),
                                                   _number(side["success"], (*path, key, "success"), True))
           for key, side in sides.items()},
    )


__all__ = ["RESULTS_FORMAT", "UNITS", "UNIFORMITY_DEFINITION", "Cluster", "Config", "Effects", "Logistic", "PerK",
           "PerRK", "Results", "SizeBin", "SizeSide", "SizeSuccess", "SizeTest", "Stat", "TypeEffects",
           "as_results", "current_results", "k_key", "r_key"]
