"""The results of :func:`~affordance_learning.paper.protocol.run_protocol`: :class:`Results`, the typed, read-only
results that the protocol builds and every report, figure and check reads; their format and units; the reading of
older ones.

Units (:data:`UNITS`, also written into every results dict as ``config["units"]``): every share is a fraction
in [0, 1] (uniformity, SVM accuracy and its baseline, the shape and size shares of the selected features, the
share of successes, purity); sizes and distances are in metres, times in seconds. Reports and figures show
shares as percentages.

:class:`Results` and its parts are written to the results dict (``results.json``) and read back by
:mod:`affordance_learning.common.typed_json`, from their types: the dict keys a map size k by :func:`k_key`
(``str(k)``: "2", "3", ...) and a relevancy threshold r by :func:`r_key` (``str(float(r))``: "0.0", "0.2", ...);
:class:`Results` keys them by number, so that no reader handles those strings.

Format 1 (written before ``results_format`` existed) gave the uniformity in percent; :func:`current_results`
upgrades it to format 2 before it is read, so reports, figures and claims can be drawn from a ``results.json``
of either. A newer format is refused, naming it.
"""

from __future__ import annotations

import copy
import numbers
from collections.abc import Iterable, Iterator, Mapping, MutableMapping
from dataclasses import dataclass, field, fields
from types import MappingProxyType
from typing import Annotated, Any

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.typed_json import from_json, json_options, to_json

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
_EXPECTED = "expected the results of run_protocol (Results.to_dict(), or its results.json read back)"

#: How the results key a map size k, a relevancy threshold r, and a count, for the messages on a value not of them.
K = Annotated[int, "a map size k"]
R = Annotated[float, "a relevancy threshold r"]
Count = Annotated[int, "a count"]


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
            if isinstance(entry, MutableMapping) and _is_number(entry.get(key)):  # others are refused when read
                entry[key] = entry[key] / 100.0
    upgraded["results_format"] = RESULTS_FORMAT
    return upgraded


def _section() -> Any:
    """A section of :class:`Results`: None, and then left out of the results dict, when the results lack it."""
    return field(default=None, metadata=json_options(omit_none=True))


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


#: A number per map size k (k -> :class:`Stat`), read-only, in the order the results hold it.
PerK = Mapping[K, Stat]
#: A number per relevancy threshold r and map size k (r -> k -> :class:`Stat`), read-only, in the order held.
PerRK = Mapping[R, PerK]
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

    index: Count = field(metadata=json_options(key="cluster"))
    success: Count
    fail: Count
    types: Mapping[str, Count]
    sizes: tuple[float, ...] = field(repr=False)
    left_view: Count | None = field(default=None, metadata=json_options(omit_none=True))

    @property
    def n(self) -> int:
        """The interactions in the cluster."""
        return self.success + self.fail


@dataclass(frozen=True)
class SizeBin:
    """One bin of object sizes: its bounds [m], its interactions and their share of successes (None when empty)."""

    low: float
    high: float
    n: Count
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

    n: Count
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


@dataclass(frozen=True)
class TypeEffects:
    """What the effects of one object type contain (:func:`affordance_learning.paper.diagnostics.effect_summary`): its
    interactions; the shares (fractions) of successes, of objects at rest, seen in the final snapshot and off the
    table; the medians of the travel [m], of the 3-D motion seen [m], of the change of the pixel count [pixels] and
    of the normal histograms (sum of |effect| over the shape features). None where the dataset could not say."""

    n: Count
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


@dataclass(frozen=True)
class Config:
    """The settings a results dict records (``config``): read through the typed properties what is computed on,
    and through :meth:`get` and :meth:`items` anything else, as written (the protocol's and ``affordance
    reproduce``'s settings, for the reports to list). The JSON holds the settings themselves."""

    entries: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}),
                                       metadata=json_options(inline=True))

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
    """The results of :func:`~affordance_learning.paper.protocol.run_protocol` (or of its ``results.json``, read
    with :meth:`from_dict`), typed and read-only, in the current format.

    Every section is None when the results lack it (results may be partial: the claims on what they hold are
    still judged). Map sizes k are ints, relevancy thresholds r floats; each mapping keeps the order the results
    hold. Shares are fractions in [0, 1] (:data:`UNITS`). The fields are in the order ``results.json`` holds
    them.

    Attributes:
        results_format: The format (:data:`RESULTS_FORMAT`; format 1 is upgraded when read).
        uniformity: Uniformity of the clusters against the success/fail labels, per k [fraction].
        svm_accuracy: SVM accuracy on held-out interactions, per r and k [fraction].
        shape_fraction: Share of shape features among the selected ones, per r and k [fraction].
        size_fraction: Share of size features among the selected ones, per r and k [fraction].
        n_selected: Number of selected features, per r and k.
        case_studies: The clusters of the 1 x k maps of the first trial, per k.
        prototypes: The prototype effect of each node of those maps, per k, in feature units (one row per node,
            one value per feature of :attr:`feature_names`).
        feature_names: The names of the features.
        effects: What the effects contain.
        size_success: How success depends on object size.
        purity: Purity of the clusters against the object type, per k [fraction].
        adjusted_rand: Adjusted Rand index of the clusters against the object type, per k.
        n_categories: Non-empty clusters, per k.
        svm_baseline: Accuracy of always answering the most common training category, per k [fraction].
        feature_weights: The mean ReliefF weight of each feature, per k.
        config: The recorded settings.
    """

    results_format: int = RESULTS_FORMAT
    uniformity: PerK | None = _section()
    svm_accuracy: PerRK | None = _section()
    shape_fraction: PerRK | None = _section()
    size_fraction: PerRK | None = _section()
    n_selected: PerRK | None = _section()
    case_studies: Mapping[K, tuple[Cluster, ...]] | None = _section()
    prototypes: Mapping[K, tuple[tuple[float, ...], ...]] | None = _section()
    feature_names: tuple[str, ...] | None = _section()
    effects: Effects | None = _section()
    size_success: SizeSuccess | None = _section()
    purity: PerK | None = _section()
    adjusted_rand: PerK | None = _section()
    n_categories: PerK | None = _section()
    svm_baseline: PerK | None = _section()
    feature_weights: Mapping[K, Mapping[str, float]] | None = _section()
    config: Config = field(default_factory=Config)

    @classmethod
    def from_dict(cls, results: Results | Mapping[str, Any], required: Iterable[str] = ()) -> Results:
        """Read a results dict (of any format this package reads, :func:`current_results`) and check it.

        Args:
            results: The dict of :meth:`to_dict` (a ``results.json`` read back), or part of it; or Results.
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
            raise InvalidValueError(f"results must be a mapping, {_EXPECTED}, got {type(results).__name__}.")
        parsed = from_json(cls, current_results(results), name="results", expected=_EXPECTED)
        parsed.check_required(required)
        return parsed

    def to_dict(self) -> dict[str, Any]:
        """The results dict of the current format, as ``results.json`` holds it: the sections held, in the order
        of the fields, with k and r keyed by :func:`k_key` and :func:`r_key`."""
        return to_json(self)

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


#: The sections of a results dict, as :class:`Results` names them.
_SECTIONS = tuple(f.name for f in fields(Results) if f.name not in ("results_format", "config"))


def as_results(results: Results | Mapping[str, Any], required: Iterable[str] = ()) -> Results:
    """``results`` as :class:`Results` (read with :meth:`Results.from_dict` unless it is one), with the
    ``required`` sections."""
    return Results.from_dict(results, required)


def _count_or_none(value: Any) -> int | None:
    return int(value) if _is_number(value) else None


def _is_number(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


__all__ = ["RESULTS_FORMAT", "UNITS", "UNIFORMITY_DEFINITION", "Cluster", "Config", "Effects", "Logistic", "PerK",
           "PerRK", "Results", "SizeBin", "SizeSide", "SizeSuccess", "SizeTest", "Stat", "TypeEffects",
           "as_results", "current_results", "k_key", "r_key"]
