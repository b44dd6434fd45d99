"""The packages' layering: the environment never depends on the learning package."""

import ast
import subprocess
import sys
from pathlib import Path

import affordance_env


def _imported_modules(path: Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
    return names


def test_affordance_env_never_imports_affordance_learning():
    package = Path(affordance_env.__file__).parent
    offenders = {str(path.relative_to(package)): sorted(m for m in _imported_modules(path)
                                                        if m.split(".")[0] == "affordance_learning")
                 for path in package.rglob("*.py")}
    assert not {k: v for k, v in offenders.items() if v}


def _loaded_after(code: str, watched: str) -> list[str]:
    """The modules of ``watched`` (a Python expression over ``sys.modules``' names ``m``, e.g. ``m in ('mujoco',)``)
    loaded in a fresh interpreter after running ``code``."""
    probe = f"{code}; import sys; print(sorted(m for m in sys.modules if {watched}))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return eval(out.stdout.strip())  # a printed list of names


def test_using_the_environment_loads_nothing_of_the_learning_package():
    code = ("import numpy as np, affordance_env, affordance_env.dataset, affordance_env.collect_cli; "
            "from affordance_env.tap_env import TapAffordanceEnv; e = TapAffordanceEnv(camera_width=32, "
            "camera_height=24); e.reset(seed=0); e.step(np.zeros(3))")
    assert _loaded_after(code, "m.startswith('affordance_learning')") == []


def test_checking_a_collections_options_loads_neither_mujoco_nor_pinocchio():
    # The coordinating process of a collection checks the options, then only schedules workers.
    code = ("from affordance_env.dataset.collect import _full_options; "
            "_full_options({'behavior': 'push', 'size_range': (0.05, 0.08)})")
    assert _loaded_after(code, "m in ('mujoco', 'pinocchio', 'affordance_env.tap_env')") == []


def test_motion_imports_no_behaviour():
    # The motion executor takes neutral targets (a palm position, a HandTarget, joint targets) and the posture per
    # call: the behaviours (their plans, strokes, grasps) build on it, not the other way round.
    motion = Path(affordance_env.__file__).parent / "motion.py"
    assert not {m for m in _imported_modules(motion) if m.startswith("affordance_env.behaviors")}


def test_the_envs_touch_no_private_attribute_of_another_object():
    # The envs adapt the world to Gymnasium through its public API only: no ``other._name`` in them.
    package = Path(affordance_env.__file__).parent
    for name in ("tap_env.py", "goal_env.py"):
        offenders = [f"{name}:{node.lineno} {ast.unparse(node)}" for node in ast.walk(ast.parse((package / name)
                                                                                                .read_text()))
                     if isinstance(node, ast.Attribute) and node.attr.startswith("_")
                     and not node.attr.startswith("__")
                     and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))]
        assert not offenders, offenders


def test_adding_a_behaviour_is_one_module_and_one_registry_line():
    # Every behaviour the registry names is defined, under that name, by the module it names, and every behaviour
    # a module of affordance_env.behaviors defines is registered with that module.
    import importlib
    import pkgutil

    from affordance_env import behaviors, registry

    for info in pkgutil.iter_modules(behaviors.__path__):
        module = importlib.import_module(f"affordance_env.behaviors.{info.name}")
        for name, behavior in getattr(module, "BEHAVIORS", {}).items():
            assert behavior.name == name and registry.REGISTERED[name].module == info.name
    for name, entry in registry.REGISTERED.items():
        assert name in importlib.import_module(f"affordance_env.behaviors.{entry.module}").BEHAVIORS


def _learning_imports(room: str) -> dict[str, list[str]]:
    import affordance_learning

    package = Path(affordance_learning.__file__).parent / room
    return {str(path.relative_to(package.parent)): sorted(m for m in _imported_modules(path)
                                                          if m.startswith("affordance_learning"))
            for path in package.rglob("*.py")}


def test_learning_rooms_are_layered_common_below_paper_below_planning():
    # common/ serves both experiments and knows neither; the paper's experiment knows nothing of the planner; the
    # planner may use the paper (its effect categories are a baseline). The command line and the default models
    # stand on top.
    allowed = {"common": ("affordance_learning.common",),
               "paper": ("affordance_learning.common", "affordance_learning.paper"),
               "planning": ("affordance_learning.common", "affordance_learning.paper", "affordance_learning.planning")}
    for room, ok in allowed.items():
        imports = _learning_imports(room)
        assert imports, f"no modules found in affordance_learning/{room}"
        offenders = {path: [m for m in names if not m.startswith(ok)] for path, names in imports.items()}
        assert not {k: v for k, v in offenders.items() if v}, offenders


def test_importing_the_planner_loads_neither_mujoco_nor_pinocchio():
    # A planner runs where its effect models are, not the simulator: its goals and the table top's extent are
    # plain numbers, read without compiling a scene.
    assert _loaded_after("import affordance_learning.planning.planner", "m in ('mujoco', 'pinocchio')") == []


def test_the_documented_submodules_resolve_after_importing_the_package_alone():
    # help(affordance_env.tap_env.TapAffordanceEnv) and affordance_env.workspace.WORKSPACES, as the README names
    # them, after nothing but ``import affordance_env``; the import itself still loads no simulator.
    code = ("import sys, affordance_env; light = 'mujoco' not in sys.modules; "
            "print(light, affordance_env.tap_env.TapAffordanceEnv.__name__, "
            "affordance_env.goal_env.FlatActionWrapper.__name__, bool(affordance_env.workspace.WORKSPACES), "
            "hasattr(affordance_env, 'no_such_module'))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["True", "TapAffordanceEnv", "FlatActionWrapper", "True", "False"]
