"""One reader and writer between frozen dataclasses and JSON (:mod:`affordance_learning.common.typed_json`): what it
writes, what it reads back, and the messages that name a value not of its type."""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Annotated, Any

import pytest

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.typed_json import from_json, json_options, to_json
from affordance_learning.planning.results import Calibration, CalibrationBin, Episode, GoalRecord, Share


@dataclass(frozen=True)
class Point:
    x: float
    y: float


@dataclass(frozen=True)
class Wrapper:
    entries: Mapping[str, Any] = field(metadata=json_options(inline=True))


@dataclass(frozen=True)
class Sample:
    name: str
    per_k: Mapping[Annotated[int, "a map size k"], Point]
    per_r: Mapping[float, Annotated[int, "a count"]]
    path: tuple[Point, ...]
    pair: tuple[float | None, int]
    flag: bool
    settings: Wrapper
    index: int = field(default=0, metadata=json_options(key="cluster"))
    note: str | None = field(default=None, metadata=json_options(omit_none=True))
    nested: Sample | None = None


SAMPLE = Sample("a", MappingProxyType({2: Point(0.5, 1)}), MappingProxyType({0: 3, 0.4: 1}),
                (Point(0.0, 1.0),), (None, 4), True, Wrapper(MappingProxyType({"ks": [2, 3], "svm": {"C": 1.0}})),
                index=7)


def test_a_dataclass_is_written_as_plain_json_keyed_as_the_results_key_k_and_r() -> None:
    written = to_json(SAMPLE)
    assert written == {"name": "a", "per_k": {"2": {"x": 0.5, "y": 1.0}}, "per_r": {"0.0": 3, "0.4": 1},
                       "path": [{"x": 0.0, "y": 1.0}], "pair": [None, 4], "flag": True,
                       "settings": {"ks": [2, 3], "svm": {"C": 1.0}}, "cluster": 7, "nested": None}
    assert isinstance(written["per_k"]["2"]["y"], float)  # a float field holds a float, 1.0 not 1
    assert json.dumps(written)  # plain JSON
    assert list(to_json(Point(1.0, 2.0))) == ["x", "y"]  # in the order of the fields


def test_what_is_written_is_read_back_equal_and_read_only() -> None:
    read = from_json(Sample, json.loads(json.dumps(to_json(SAMPLE))))
    assert read == SAMPLE and read.per_r[0.0] == 3 and read.per_k[2] == Point(0.5, 1.0)
    with pytest.raises(TypeError):
        read.per_k[3] = Point(0.0, 0.0)  # type: ignore[index]
    with_note = Sample(**{**SAMPLE.__dict__, "note": "n", "nested": SAMPLE})
    assert from_json(Sample, to_json(with_note)) == with_note and to_json(with_note)["note"] == "n"


def test_any_is_copied_so_the_json_read_stays_apart() -> None:
    data = to_json(SAMPLE)
    read = from_json(Sample, data)
    data["settings"]["ks"].append(4)
    assert read.settings.entries["ks"] == [2, 3]


@pytest.mark.parametrize(("edit", "message"), [
    (lambda d: d.pop("flag"), r"sample lacks 'flag'; expected a sample\.$"),
    (lambda d: d["per_k"].update(two={"x": 0, "y": 0}),
     r"sample\['per_k'\] holds the key 'two', which is not a map size k \(a whole number, written as str\(int"),
    (lambda d: d["per_r"].update(high=1), r"holds the key 'high', which is not a number \(written as str\(float"),
    (lambda d: d["per_r"].update({"0.4": 1.5}), r"sample\['per_r'\]\['0.4'\] must be a count \(a whole number\), "
                                                r"got 1.5"),
    (lambda d: d["per_k"]["2"].pop("y"), r"sample\['per_k'\]\['2'\] lacks 'y'"),
    (lambda d: d["path"][0].update(x="1"), r"sample\['path'\]\[0\]\['x'\] must be a number, got '1'"),
    (lambda d: d.update(pair=[None]), r"sample\['pair'\] must be a list of 2 values, got \[None\]"),
    (lambda d: d.update(pair=[None, None]), r"sample\['pair'\]\[1\] must be a whole number, got None"),
    (lambda d: d.update(flag="false"), r"sample\['flag'\] must be true or false, got 'false'"),
    (lambda d: d.update(flag=1), r"must be true or false, got 1"),
    (lambda d: d.update(path={}), r"sample\['path'\] must be a list, got dict"),
    (lambda d: d.update(settings=[]), r"sample\['settings'\] must be a mapping, got list"),
    (lambda d: d.update(note=3), r"sample\['note'\] must be a text or None, got 3"),
    (lambda d: d.update(nested={"name": "b"}), r"sample\['nested'\] lacks 'per_k', 'per_r', 'path', 'pair'"),
])
def test_a_value_not_of_its_type_is_named_with_where_it_lies(edit, message: str) -> None:
    data = to_json(SAMPLE)
    edit(data)
    with pytest.raises(InvalidValueError, match=message):
        from_json(Sample, data, name="sample", expected="expected a sample")


def test_a_field_with_a_default_may_be_missing_and_keys_no_field_names_are_skipped() -> None:
    data = {k: v for k, v in to_json(SAMPLE).items() if k not in ("cluster", "nested")}
    read = from_json(Sample, {**data, "written_later": 1})
    assert read.index == 0 and read.nested is None and read.note is None


def test_a_type_it_does_not_read_is_a_programming_error() -> None:
    @dataclass(frozen=True)
    class Odd:
        value: float | str

    with pytest.raises(TypeError, match="only X | None"):
        from_json(Odd, {"value": 1.0})


def test_the_plans_records_read_through_it() -> None:
    # The plan's types as they are: goal records, episodes with their optional mapping of flags, shares with an
    # interval, and a calibration that holds another.
    goal = {"kind": "roll", "type": "sphere", "object": 3, "planner": True, "planner_p": 0.8,
            "planner_behavior": "tap", "oracle": True, "size": 0.05}
    read = from_json(GoalRecord, goal, name="plan results")
    assert read == GoalRecord(kind="roll", type="sphere", object=3, planner=True, planner_p=0.8,
                              planner_behavior="tap", oracle=True, size=0.05)
    assert to_json(read) == {**goal, "oracle_hits": None, "planner_left_out": None, "placement_error": None}
    with pytest.raises(InvalidValueError, match=r"plan results\['planner'\] must be true or false, got 'false'"):
        from_json(GoalRecord, {**goal, "planner": "false"}, name="plan results")
    episode = Episode(type="box", start_xy=(-0.3, 0.0), target_xy=(-0.2, 0.1), success=False, within_reach=True,
                      gave_up=False, failures=("reach",), toward_robot=True,
                      pulls_at_start=MappingProxyType({"draw": True, "grasp": False}))
    assert from_json(Episode, json.loads(json.dumps(to_json(episode)))) == episode
    assert from_json(Share, to_json(Share(0.5, 20, (0.3, 0.7)))) == Share(0.5, 20, (0.3, 0.7))
    pooled = Calibration(0.1, None, 4, (CalibrationBin(0.5, 0.25, 4),))
    calibration = Calibration(0.05, 0.9, 2, (), basis="chosen", pooled=pooled)
    assert from_json(Calibration, to_json(calibration)) == calibration
