"""The reproducibility contract: bit for bit with one set of versions on one kind of CPU, labels across machines.

The simulation's numbers must not depend on which OpenBLAS kernels numpy's BLAS picks for the CPU it runs on
(:mod:`affordance_env.linalg`): ``OPENBLAS_CORETYPE`` makes one CPU stand for several.
"""

import ast
import copy
import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from affordance_env.dataset.fingerprint import (
    MAX_LABEL_CHANGES,
    compare_fingerprints,
    made_with,
    making_differences,
)

ROOT = Path(__file__).resolve().parent.parent


def _pinned(n: int = 5) -> dict:
    interactions = [{"episode": e, "seed": 100 + e, "type": "sphere", "success": e % 2 == 0, "outcome": "rolled",
                     "sha256": {part: f"{part}{e}" for part in ("action", "truth", "initial", "final", "effect")}}
                    for e in range(n)]
    return {"episodes": n, "settings": {"seed": 0, "action": "canonical", "env_options": {"behavior": "tap"}},
            "failures": {}, "made_with": made_with(), "interactions": interactions}


def _elsewhere(pinned: dict) -> dict:
    other = copy.deepcopy(pinned)
    other["made_with"]["packages"]["mujoco"] = "0.0.1"
    return other


def test_made_with_records_the_versions_and_the_cpu():
    found = made_with()
    assert set(found["packages"]) >= {"mujoco", "numpy", "pin", "scipy", "scikit-learn"}
    assert found["packages"]["numpy"] == np.__version__ and found["python"].count(".") == 2
    assert found["cpu"]["machine"] and "SSE2" in found["cpu"]["features"]
    assert making_differences(found, made_with()) == []
    other = copy.deepcopy(found)
    other["packages"]["mujoco"], other["cpu"]["features"] = "9.9", [*found["cpu"]["features"], "AVX1024"]
    assert making_differences(other, found) == [f"mujoco 9.9 here {found['packages']['mujoco']}",
                                                 "CPU features -AVX1024"]
    assert making_differences(None, found) == ["the fingerprint does not record what it was made with"]


def test_with_the_same_versions_and_cpu_the_check_is_bit_for_bit():
    pinned = _pinned()
    same = compare_fingerprints(pinned, copy.deepcopy(pinned))
    assert same.ok and same.mode == "bit for bit" and same.identical == 5 and same.summary().startswith("bit for bit")
    nudged = copy.deepcopy(pinned)
    nudged["interactions"][3]["sha256"]["final"] = "other"  # one last bit of the final features
    check = compare_fingerprints(pinned, nudged)
    assert not check.ok and check.problems == ("episode 3 (sphere): final changed",) and check.identical == 4


def test_across_machines_the_check_holds_the_labels_not_the_bits():
    pinned = _pinned()
    found = _elsewhere(pinned)
    for interaction in found["interactions"]:
        interaction["sha256"]["truth"] = "chaotic"  # every final pose differs a little
    check = compare_fingerprints(pinned, found)
    assert check.ok and check.mode == "across machines" and check.identical == 0
    assert "mujoco" in check.summary() and "0 of 5 outcome labels changed" in check.summary()
    for e in range(MAX_LABEL_CHANGES):
        found["interactions"][e]["success"] = not found["interactions"][e]["success"]
    assert compare_fingerprints(pinned, found).ok  # as many label changes as allowed
    found["interactions"][MAX_LABEL_CHANGES]["outcome"] = "slid"
    check = compare_fingerprints(pinned, found)
    assert not check.ok and check.labels_changed == MAX_LABEL_CHANGES + 1
    assert f"{MAX_LABEL_CHANGES + 1} outcome labels changed" in check.problems[0]


def test_across_machines_the_same_interactions_are_drawn():
    pinned = _pinned()
    found = _elsewhere(pinned)
    found["interactions"][1]["type"] = "box"  # the seed decides the object: it cannot depend on the machine
    check = compare_fingerprints(pinned, found)
    assert not check.ok and check.problems == ("episode 1: drew box (seed 101) instead of sphere (seed 101)",)
    failed = _elsewhere(pinned)
    del failed["interactions"][0:MAX_LABEL_CHANGES + 1]  # failed interactions are labels too
    assert not compare_fingerprints(pinned, failed).ok


def test_a_fingerprint_without_its_making_is_checked_across_machines():
    pinned = _pinned()
    del pinned["made_with"]
    check = compare_fingerprints(pinned, _pinned())
    assert check.mode == "across machines" and check.ok


#: numpy products and solvers that hand their work to BLAS, whose kernels depend on the CPU.
_BLAS_CALLS = {"dot", "matmul", "inner", "vdot", "tensordot", "solve", "lstsq", "inv", "pinv", "norm"}


def test_the_simulation_leaves_no_arithmetic_to_blas():
    offenders = []
    for path in sorted((ROOT / "affordance_env").rglob("*.py")):
        if path.name == "linalg.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.BinOp | ast.AugAssign) and isinstance(node.op, ast.MatMult):
                offenders.append(f"{path.name}:{node.lineno} @")
            elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in _BLAS_CALLS
                  and ast.unparse(node.func.value) in {"np", "np.linalg", "numpy", "numpy.linalg"}
                  and not (node.func.attr == "norm" and any(k.arg == "axis" for k in node.keywords))):
                offenders.append(f"{path.name}:{node.lineno} {ast.unparse(node.func)}")
    assert offenders == [], "use affordance_env.linalg instead"


_PROBE = """
import hashlib, sys
import numpy as np, gymnasium as gym
import affordance_env  # noqa: F401
digest = hashlib.sha256()
for behavior in sys.argv[1:]:
    env = gym.make("TapAffordance-v2", behavior=behavior, camera_width=40, camera_height=30)
    env.action_space.seed(0)
    for seed in range(2):
        env.reset(seed=seed)
        obs, _, _, _, info = env.step(env.action_space.sample())
        digest.update(np.asarray(info["effect"], dtype=np.float64).tobytes())
        digest.update(np.asarray(env.unwrapped.physics.data.qpos, dtype=np.float64).tobytes())
print(digest.hexdigest())
"""


@pytest.mark.slow
def test_interactions_do_not_depend_on_the_blas_kernels_of_the_cpu():
    # Haswell (AVX2), SkylakeX (AVX-512), Sandybridge (AVX without FMA): what numpy's OpenBLAS picks on other CPUs.
    # Their products differ in the last bits (checked below), the interactions must not.
    digests = {}
    for core in ("Haswell", "SkylakeX", "Sandybridge"):
        env = {**os.environ, "OPENBLAS_CORETYPE": core}
        check = subprocess.run([sys.executable, "-c", "import numpy as np; r = np.random.default_rng(0); "
                                "a = r.normal(size=(8, 300)); print((a @ a.T).tobytes().hex())"],
                               env=env, capture_output=True, text=True, check=True)
        run = subprocess.run([sys.executable, "-c", _PROBE, "tap", "grasp"], env=env, capture_output=True, text=True,
                             check=True, cwd=ROOT)
        digests[core] = (hashlib.sha256(check.stdout.encode()).hexdigest(), run.stdout.strip())
    blas = {products for products, _ in digests.values()}
    if len(blas) == 1:  # numpy without OpenBLAS (MKL, Accelerate): nothing to choose between here
        pytest.skip("OPENBLAS_CORETYPE changes nothing in this numpy's BLAS")
    assert len({interactions for _, interactions in digests.values()}) == 1, json.dumps(digests)


def _results(uniformity_k3: float = 0.77, success: float = 0.5, std: float = 0.05) -> dict:
    config = {"behavior": "tap", "seed": 0, "episodes": 1000, "ks": [2, 3], "relevancies": [0.0],
              "range_noise": "none", "n_trials": 20, "n_rows": 1000, "success_fraction": success}
    return {"results_format": 2, "config": config,
            "uniformity": {"2": {"mean": 0.40, "std": 0.3}, "3": {"mean": uniformity_k3, "std": std}},
            "svm_accuracy": {"0.0": {"2": {"mean": 0.95, "std": 0.01}, "3": {"mean": 0.92, "std": 0.01}}}}


def test_two_reproductions_agree_within_the_trials_own_spread():
    from affordance_learning.paper.agreement import FLOOR, Z, compare_results

    same = compare_results(_results(), _results(uniformity_k3=0.80))  # 3 points at a spread of 5 points
    assert all(c.ok for c in same) and len(same) == 1 + 2 + 2
    k3 = next(c for c in same if c.name == "uniformity at k = 3")
    p = (0.77 + 0.80) / 2  # the trials' spread and the 1000 interactions' binomial share, in quadrature
    assert k3.tolerance == pytest.approx(Z * (2 * 0.05 ** 2 / 20 + 2 * p * (1 - p) / 1000) ** 0.5)
    moved = compare_results(_results(), _results(uniformity_k3=0.87))
    assert [c.name for c in moved if not c.ok] == ["uniformity at k = 3"] and "outside" in str(moved[2])
    alike = compare_results(_results(std=0.0), _results(uniformity_k3=0.78, std=0.0))  # every trial the same
    assert next(c for c in alike if c.name == "uniformity at k = 3").ok  # the interactions still vary
    certain = _results(uniformity_k3=1.0, std=0.0)
    assert next(c for c in compare_results(certain, certain) if c.name == "uniformity at k = 3").tolerance == FLOOR
    fewer = compare_results(_results(), _results(success=0.58))  # 8 points more successes of 1000
    assert [c.name for c in fewer if not c.ok] == ["share of successes"]


def test_a_number_whose_trials_disagree_is_shown_but_not_held_to_a_tolerance():
    from affordance_learning.paper.agreement import UNSTABLE_SPREAD, compare_results

    unstable = compare_results(_results(std=UNSTABLE_SPREAD + 0.05), _results(uniformity_k3=0.40))
    k3 = next(c for c in unstable if c.name == "uniformity at k = 3")
    assert not k3.held and k3.ok and "not held to a tolerance: its trials spread by 15 points" in str(k3)
    k2 = next(c for c in unstable if c.name == "uniformity at k = 2")  # a spread of 30 points in the fixture
    assert not k2.held
    stable = compare_results(_results(std=UNSTABLE_SPREAD), _results(uniformity_k3=0.40))
    assert not next(c for c in stable if c.name == "uniformity at k = 3").ok


def test_only_reproductions_of_the_same_experiment_are_compared():
    from affordance_learning.paper.agreement import compare_results

    other = _results()
    other["config"]["seed"] = 1
    with pytest.raises(ValueError, match="seed 1 \\(reference 0\\)"):
        compare_results(_results(), other)


def test_compare_command_sets_numbers_beside_the_reference(tmp_path, capsys):
    from affordance_learning.cli import main

    reference = ROOT / "docs" / "reproduction" / "tap"
    assert main(["compare", str(reference), str(reference)]) == 0
    out = capsys.readouterr().out
    assert "54 of 54 numbers within their tolerances; 1 whose trials spread" in out and "uniformity at k = 8" in out
    moved = json.loads((reference / "results.json").read_text())
    moved["uniformity"]["8"]["mean"] -= 0.2
    (tmp_path / "results.json").write_text(json.dumps(moved))
    assert main(["compare", str(reference), str(tmp_path)]) == 1
    assert "uniformity at k = 8" in capsys.readouterr().out.split("outside")[0].splitlines()[-1]
    assert main(["compare", str(reference), str(tmp_path / "nothing")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "holds no results.json" in err


def test_results_without_the_compared_numbers_are_named(tmp_path, capsys):
    from affordance_learning.cli import main

    (tmp_path / "results.json").write_text(json.dumps({"config": {"behavior": "tap"}}))
    assert main(["compare", str(ROOT / "docs" / "reproduction" / "tap"), str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "the found results lack uniformity, svm_accuracy, config.n_rows" in err


def test_a_numerical_failure_in_the_simulation_is_no_users_mistake():
    from affordance_env.linalg import lstsq, solve_spd

    with pytest.raises(np.linalg.LinAlgError):
        solve_spd(-np.eye(2), np.ones(2))
    with pytest.raises(np.linalg.LinAlgError):
        lstsq(np.array([[1.0, np.nan], [0.0, 1.0]]), np.ones(2))
    from affordance_env.exceptions import AffordanceEnvError

    assert not issubclass(np.linalg.LinAlgError, AffordanceEnvError)  # the CLI keeps its traceback
