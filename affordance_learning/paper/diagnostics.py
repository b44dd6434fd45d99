"""What the effects of a dataset contain, measured once over all its rows (a diagnostic beside the protocol)."""

from __future__ import annotations

from types import MappingProxyType

import numpy as np
import pandas as pd

from affordance_learning.common.schema import TYPE_ORDER, feature_groups, feature_names, label_column
from affordance_learning.paper.results import Effects, TypeEffects


def effect_summary(frame: pd.DataFrame) -> Effects:
    """What the effects of a dataset contain, for a reader to check before any verdict.

    Per object type (``by_type``): interactions, the shares of successes (the ``success`` label, or
    ``rolled`` for a frame without it), at rest and seen in the final snapshot (``visible_final``), and left
    the table (``outcome == "off_table"``); the median travel (``displacement``) [m], the median 3-D motion
    seen, ``|effect of (mean_x, mean_y, mean_z)|`` [m], over the objects seen at the end, the median
    ``|effect of pixel_count|`` [pixels] and the median change of the normal histograms (sum of ``|effect|``
    over the 24 shape features). Overall: the share of successes whose object is seen at the end
    (``success_visible``; at rest and seen: ``success_rest_visible``), the share of successes whose effect is
    just minus their initial features (``success_effect_is_minus_initial``: the object vanished), and the
    Spearman correlation of the travel with the 3-D motion seen (``travel_vs_seen_motion``). Columns the frame
    lacks give None.
    """
    names = feature_names(frame)
    groups = feature_groups(names)
    xyz = [f"effect_{n}" for n in ("mean_x", "mean_y", "mean_z") if n in names]
    seen_motion = (np.linalg.norm(frame[xyz].to_numpy(dtype=np.float64), axis=1) if len(xyz) == 3
                   else np.full(len(frame), np.nan))
    shape_change = np.abs(frame[[f"effect_{n}" for n, g in zip(names, groups, strict=True) if g == "shape"]]
                          .to_numpy(dtype=np.float64)).sum(axis=1)
    initial = frame[[f"initial_{n}" for n in names]].to_numpy(dtype=np.float64)
    effect = frame[[f"effect_{n}" for n in names]].to_numpy(dtype=np.float64)
    vanished = np.abs(effect + initial).max(axis=1) < 1e-6
    visible = frame["visible_final"].to_numpy(dtype=bool) if "visible_final" in frame else None
    outcome = frame["outcome"].astype(str).to_numpy() if "outcome" in frame else None
    travel = frame["displacement"].to_numpy(dtype=np.float64) if "displacement" in frame else None
    success = frame[label_column(frame)].to_numpy(dtype=bool)
    pixels = (np.abs(frame["effect_pixel_count"].to_numpy(dtype=np.float64)) if "pixel_count" in names
              else np.full(len(frame), np.nan))

    def share(mask: np.ndarray | None, rows: np.ndarray) -> float | None:
        return None if mask is None or not rows.any() else float(np.mean(mask[rows]))

    def median(values: np.ndarray | None, rows: np.ndarray) -> float | None:
        if values is None or not rows.any():
            return None
        finite = values[rows][np.isfinite(values[rows])]
        return float(np.median(finite)) if finite.size else None

    types = frame["type"].astype(str).to_numpy()
    by_type = {}
    for t in [t for t in TYPE_ORDER if t in set(types)] + sorted(set(types) - set(TYPE_ORDER)):
        rows = types == t
        seen = rows & visible if visible is not None else rows
        by_type[t] = TypeEffects(
            n=int(rows.sum()),
            success=share(success, rows),
            rest=share(None if outcome is None else outcome == "rest", rows),
            visible_final=share(visible, rows),
            off_table=share(None if outcome is None else outcome == "off_table", rows),
            displacement=median(travel, rows),
            seen_motion=median(seen_motion, seen),
            pixel_count_change=median(pixels, rows),
            shape_change=median(shape_change, rows),
        )
    correlation = None
    if travel is not None and visible is not None and visible.sum() >= 3:
        from scipy.stats import spearmanr

        correlation = float(spearmanr(travel[visible], seen_motion[visible]).statistic)
    return Effects(
        by_type=MappingProxyType(by_type),
        success_visible=share(visible, success),
        success_rest_visible=None if visible is None or outcome is None else share(
            visible & (outcome == "rest"), success),
        success_effect_is_minus_initial=share(vanished, success),
        travel_vs_seen_motion=correlation,
    )
