"""One vocabulary of verdicts for both experiments: the paper's claims and the planner's targets.

A statement to check (a claim of the paper, a target of the planner) is a :class:`Spec`: what is stated, the rule
as a reader sees it, the judge that applies the rule to the results, the basis that says how much data the verdict
stands on, and an optional *why* that explains from the data a statement the results do not bear out. :func:`judge`
turns a spec and the results into a :class:`Verdict`, by one rule for both experiments:

- ``"not measured"`` when the results lack what the rule needs, or do not say how much data they hold;
- ``"too few data"`` when any count of the basis is below its minimum (:class:`Count`);
- else ``"met"`` or ``"missed"`` by the rule, and a missed one says why where its spec can.

The reports render the verdicts they are given; none dispatches on a statement's text.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Generic, TypeVar

MET = "met"
MISSED = "missed"
TOO_FEW = "too few data"
NOT_MEASURED = "not measured"
#: Every verdict word, in the order the reports count them.
WORDS = (MET, MISSED, TOO_FEW, NOT_MEASURED)

R = TypeVar("R")


class NotMeasured(Exception):
    """Raised by a judge when the results lack what its rule needs; the message says what is missing."""


@dataclass(frozen=True)
class Count:
    """One count a verdict stands on, and the least of it a verdict is given on.

    Attributes:
        n: How many (trials, interactions, goals, episodes, ...); None when the results do not say.
        minimum: The least ``n`` a verdict is given on.
        unit: What ``n`` counts, as the report writes it after the number ("trials", "feasible goals").
    """

    n: int | None
    minimum: int
    unit: str

    @property
    def enough(self) -> bool:
        return self.n is not None and self.n >= self.minimum


@dataclass(frozen=True)
class Basis:
    """What a verdict is judged on: one or more counts (for example trials, and interactions in each), all of
    which must reach their minimum; ``text`` overrides how they read ("1000 interactions in the 1 x 2 map")."""

    counts: tuple[Count, ...]
    text: str | None = None

    @property
    def n(self) -> int | None:
        """The first count, the verdict's n."""
        return self.counts[0].n if self.counts else None

    @property
    def known(self) -> bool:
        return bool(self.counts) and all(c.n is not None for c in self.counts)

    @property
    def enough(self) -> bool:
        return self.known and all(c.enough for c in self.counts)

    @property
    def judged_on(self) -> str:
        """What the verdict was judged on: "20 trials of 1000 interactions"."""
        if self.text is not None:
            return self.text
        return " of ".join(f"{c.n} {c.unit}" for c in self.counts) if self.known else "unknown"

    @property
    def needed(self) -> str:
        """The least data a verdict is given on: "10 trials of 200 interactions"."""
        return " of ".join(f"{c.minimum} {c.unit}" for c in self.counts)


@dataclass(frozen=True)
class Judgement:
    """What a judge found: the numbers as the report shows them, and whether the rule holds on them."""

    ours: str
    holds: bool

    def __post_init__(self) -> None:
        object.__setattr__(self, "holds", bool(self.holds))  # numpy's booleans too


@dataclass(frozen=True)
class Spec(Generic[R]):
    """A statement to check on results of type ``R``, before it is judged.

    Attributes:
        topic: Short name of the statement (a claim's topic, a target's name).
        statement: What is stated: the paper's words, or the target as a reader sets it.
        rule: The rule the verdict follows, as the report writes it beside the verdict.
        judge: Applies the rule to the results; raises :class:`NotMeasured` when they lack what it needs.
        basis: How much data the verdict stands on.
        why: Where the rule is missed, why from the data (None where nothing more can be said).
    """

    topic: str
    statement: str
    rule: str
    judge: Callable[[R], Judgement]
    basis: Callable[[R], Basis]
    why: Callable[[R], str | None] | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Verdict:
    """A statement judged on results.

    Attributes:
        topic, statement, rule: From its :class:`Spec`.
        ours: Our numbers, as text.
        word: One of :data:`WORDS`.
        basis: What it was judged on (its n) and the least needed.
        why: Why the rule is missed, from the data; None unless ``word`` is :data:`MISSED` and the spec can say.
    """

    topic: str
    statement: str
    rule: str
    ours: str
    word: str
    basis: Basis
    why: str | None = None

    @property
    def n(self) -> int | None:
        return self.basis.n

    @property
    def n_text(self) -> str:
        """The verdict's n as text: "n=20 trials of 1000 interactions", with what is needed when too few."""
        needed = f"; at least {self.basis.needed} needed" if self.word == TOO_FEW else ""
        return ("n unknown" if not self.basis.known else f"n={self.basis.judged_on}") + needed

    @property
    def text(self) -> str:
        """The verdict with its n: "met (n=20 trials of 1000 interactions)"."""
        return f"{self.word} ({self.n_text})"

    @property
    def met(self) -> bool | None:
        """True if met, False if missed, None without a verdict (too few data, not measured)."""
        return True if self.word == MET else False if self.word == MISSED else None


def judge(spec: Spec[R], results: R) -> Verdict:
    """Judge ``spec`` on ``results`` by the one rule of this module (see its docstring)."""
    basis = spec.basis(results)
    why = None
    try:
        judgement = spec.judge(results)
    except NotMeasured as missing:
        ours, word = f"({missing})", NOT_MEASURED
    else:
        ours = judgement.ours
        if not basis.known:
            ours, word = f"{ours} (the results do not say how much data this is)", NOT_MEASURED
        elif not basis.enough:
            word = TOO_FEW
        else:
            word = MET if judgement.holds else MISSED
            if word == MISSED and spec.why is not None:
                why = spec.why(results) or None
    return Verdict(topic=spec.topic, statement=spec.statement, rule=spec.rule, ours=ours, word=word, basis=basis,
                   why=why)


def judge_all(specs: Sequence[Spec[R]], results: R) -> list[Verdict]:
    """Every spec judged on the same results, in order."""
    return [judge(spec, results) for spec in specs]


def tally(verdicts: Sequence[Verdict]) -> dict[str, int]:
    """How many verdicts have each word, every word listed (zeros included), in the order of :data:`WORDS`."""
    return {word: sum(v.word == word for v in verdicts) for word in WORDS}


def tally_text(verdicts: Sequence[Verdict], what: str = "statements") -> str:
    """The tally as one line for a console or a report: "6 of 10 claims met, 2 missed, 2 had too few data, 0 not
    measured": every word, so that "too few data" is never hidden behind a low count of met."""
    counts = tally(verdicts)
    return (f"{counts[MET]} of {len(verdicts)} {what} met, {counts[MISSED]} missed, {counts[TOO_FEW]} had too few "
            f"data, {counts[NOT_MEASURED]} not measured")


__all__ = ["MET", "MISSED", "NOT_MEASURED", "TOO_FEW", "WORDS", "Basis", "Count", "Judgement", "NotMeasured", "Spec",
           "Verdict", "judge", "judge_all", "tally", "tally_text"]
