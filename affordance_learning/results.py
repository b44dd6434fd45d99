"""The results of :func:`~affordance_learning.protocol.run_protocol`: their format and units, and the
reading of older ones.

Units (:data:`UNITS`, also written into every results dict as ``config["units"]``): every share is a fraction
in [0, 1] (uniformity, SVM accuracy and its baseline, the shape and size shares of the selected features, the
share of successes, purity); sizes and distances are in metres, times in seconds. Reports and figures show
shares as percentages.

Format 1 (written before ``results_format`` existed) gave the uniformity in percent; :func:`current_results`
reads it as format 2, so reports, figures and claims can be drawn from an ``results.json`` of either.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from typing import Any

from affordance_learning.exceptions import InvalidValueError

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


def current_results(results: Mapping[str, Any]) -> Mapping[str, Any]:
    """``results`` in the current format: format 1 (no ``results_format``, uniformity in percent) is read as
    format 2 (a fraction) in a copy; a current one is returned as it is. A newer one raises ValueError."""
    found = results.get("results_format", 1)
    if found == RESULTS_FORMAT:
        return results
    if found != 1:
        raise InvalidValueError(
            f"results of format {found!r}; this tap-affordance reads formats 1 to {RESULTS_FORMAT}: "
                         "upgrade the package.")
    upgraded = copy.deepcopy(dict(results))
    for entry in upgraded.get("uniformity", {}).values():
        for key in ("mean", "std"):
            if entry.get(key) is not None:
                entry[key] = entry[key] / 100.0
    upgraded["results_format"] = RESULTS_FORMAT
    return upgraded
