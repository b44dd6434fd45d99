"""The cache of compiled models: a cached model is the compiled one, and any change of input is a new entry."""

from __future__ import annotations

import os
import shutil
import warnings

import mujoco
import numpy as np
import pytest

from affordance_env import model_cache, scene
from affordance_env.robot_model import icub_urdf


def _bytes(model: mujoco.MjModel) -> bytes:
    buffer = np.empty(mujoco.mj_sizeModel(model), dtype=np.uint8)
    mujoco.mj_saveModel(model, None, buffer)
    return buffer.tobytes()


@pytest.fixture(scope="module")
def compiled() -> bytes:
    """The tap model as compiling gives it, without the cache."""
    return _bytes(scene.compile_scene("tap"))


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv(model_cache.CACHE_ENV, str(tmp_path / "cache"))
    return tmp_path / "cache"


def test_a_cached_model_is_the_compiled_model_byte_for_byte(cache, compiled, monkeypatch):
    first = scene.build_model("tap")  # compiled, and stored
    (stored,) = cache.glob("model-tap-*.mjb")
    assert _bytes(first) == compiled

    def no_compiling(variant):
        raise AssertionError("the model was compiled again instead of read from the cache")

    monkeypatch.setattr(scene, "build_spec", no_compiling)
    second = scene.build_model("tap")
    assert _bytes(second) == compiled
    assert second is not first  # each env gets a model of its own to modify


def test_a_damaged_cached_model_is_compiled_again_and_replaced(cache, compiled):
    scene.build_model("tap")
    (stored,) = cache.glob("model-tap-*.mjb")
    size = stored.stat().st_size
    with open(stored, "r+b") as f:  # as a write cut short would leave it
        f.truncate(size // 2)
    assert _bytes(scene.build_model("tap")) == compiled
    assert stored.stat().st_size == size


def test_the_cache_key_changes_with_every_input(tmp_path, monkeypatch):
    mesh = tmp_path / "link.stl"
    mesh.write_bytes(b"solid a")
    urdf = f'<robot><link><visual><geometry><mesh filename="{mesh}"/></geometry></visual></link></robot>'
    key = model_cache.fingerprint("tap", (urdf,))
    assert model_cache.fingerprint("tap", (urdf,)) == key  # a pure function of the inputs
    assert model_cache.fingerprint("grasp", (urdf,)) != key
    assert model_cache.fingerprint("tap", (urdf + " ",)) != key
    mesh.write_bytes(b"solid b")  # the same URDF, another mesh
    assert model_cache.fingerprint("tap", (urdf,)) != key
    mesh.write_bytes(b"solid a")
    assets = tmp_path / "assets"
    assets.mkdir()
    for name in ("scene.xml", "README.md"):
        (assets / name).write_bytes((model_cache.assets_dir() / name).read_bytes())
    monkeypatch.setattr(model_cache, "assets_dir", lambda: assets)
    assert model_cache.fingerprint("tap", (urdf,)) == key  # the same assets, elsewhere
    (assets / "scene.xml").write_text((assets / "scene.xml").read_text().replace("</mujoco>", "</mujoco>\n"))
    assert model_cache.fingerprint("tap", (urdf,)) != key
    monkeypatch.setattr(mujoco, "__version__", mujoco.__version__ + ".1")
    assert model_cache.fingerprint("tap", (urdf,)) != key


def test_the_key_covers_the_package_source(tmp_path, monkeypatch):
    urdf = icub_urdf()
    key = model_cache.fingerprint("tap", (urdf,))
    package = tmp_path / "affordance_env"
    shutil.copytree(model_cache._PACKAGE, package, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(model_cache, "_PACKAGE", package)
    assert model_cache.fingerprint("tap", (urdf,)) == key
    with open(package / "scene.py", "a") as f:
        f.write("\nROBOT_CONTYPE = 3\n")
    assert model_cache.fingerprint("tap", (urdf,)) != key


def test_old_models_and_files_of_killed_writes_are_removed(cache, compiled):
    cache.mkdir()
    for i in range(model_cache.KEEP + 2):
        old = cache / f"model-tap-{i:032x}.mjb"
        old.write_bytes(b"old")
        os.utime(old, (1e9 + i, 1e9 + i))
    killed = cache / ".model-tap-x.mjb.abc.tmp"  # a write killed an hour ago, and one under way
    killed.write_bytes(b"half")
    os.utime(killed, (os.path.getmtime(killed) - 3600,) * 2)
    writing = cache / ".model-tap-y.mjb.def.tmp"
    writing.write_bytes(b"half")
    other = cache / f"model-grasp-{0:032x}.mjb"
    other.write_bytes(b"another variant")
    os.utime(other, (1e9, 1e9))
    scene.build_model("tap")
    kept = sorted(p.name for p in cache.glob("model-tap-*.mjb"))
    assert len(kept) == model_cache.KEEP
    assert f"model-tap-{model_cache.KEEP + 1:032x}.mjb" in kept  # the newest old one, and the new one
    assert other.exists()
    assert not killed.exists() and writing.exists()


def test_without_a_usable_cache_the_model_is_compiled(tmp_path, monkeypatch, compiled):
    monkeypatch.setenv(model_cache.CACHE_ENV, "off")
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert model_cache.cache_dir() is None
    assert _bytes(scene.build_model("tap")) == compiled
    assert not any(tmp_path.iterdir())
    blocker = tmp_path / "a-file"  # the cache directory cannot be made: a file is in the way
    blocker.write_text("")
    monkeypatch.setenv(model_cache.CACHE_ENV, str(blocker / "cache"))
    with pytest.warns(UserWarning, match=f"the model cache {blocker / 'cache'} cannot be written"):
        assert _bytes(scene.build_model("tap")) == compiled
    with warnings.catch_warnings():  # said once, not at every env: the cache is off now
        warnings.simplefilter("error")
        assert _bytes(scene.build_model("tap")) == compiled


def test_a_cache_that_cannot_be_written_is_said_once_before_workers_start(tmp_path, monkeypatch):
    # each worker of a collection said it again, as Python's raw warning
    import importlib

    from affordance_env.dataset import collect

    blocker = tmp_path / "a-file"
    blocker.write_text("")
    monkeypatch.setenv(model_cache.CACHE_ENV, str(blocker / "cache"))
    seen = []
    module = importlib.import_module("affordance_env.dataset.collect")
    monkeypatch.setattr(module, "_run", lambda tasks, scheduler, workers, client: seen.append(
        os.environ[model_cache.CACHE_ENV]) or iter(()))  # what the workers would inherit
    monkeypatch.setattr(module.os, "cpu_count", lambda: 4)
    with pytest.warns(UserWarning, match=f"the model cache {blocker / 'cache'} cannot be written") as said:
        collect(tmp_path / "taps", 4, workers=2, chunk_size=2, progress=False)
    assert len(said) == 1 and seen == ["off"]
    assert model_cache.check_cache() is None  # off now: nothing more to say


def test_the_default_directory_follows_xdg(tmp_path, monkeypatch):
    monkeypatch.delenv(model_cache.CACHE_ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert model_cache.cache_dir() == tmp_path / "tap-affordance"
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert model_cache.cache_dir() == tmp_path / "home" / ".cache" / "tap-affordance"


def _layout(root, installed: bool):
    """A copy of the package as a checkout has it (assets beside the package) or as an installed wheel has it
    (assets inside it, affordance_env/assets); returns (package, assets)."""
    package = root / "affordance_env"
    shutil.copytree(model_cache._PACKAGE, package, ignore=shutil.ignore_patterns("__pycache__", "assets"))
    assets = package / "assets" if installed else root / "assets"
    shutil.copytree(model_cache.assets_dir(), assets)
    return package, assets


def test_the_key_does_not_depend_on_where_the_package_lives(tmp_path, monkeypatch):
    urdf = icub_urdf()
    key = model_cache.fingerprint("tap", (urdf,))
    for root, installed in ((tmp_path / "checkout", False), (tmp_path / "venv" / "site-packages", True)):
        package, assets = _layout(root, installed)
        monkeypatch.setattr(model_cache, "_PACKAGE", package)
        monkeypatch.setattr(model_cache, "assets_dir", lambda assets=assets: assets)
        assert model_cache.fingerprint("tap", (urdf,)) == key, root
        (package / "notes.txt").write_text("not code")  # what a checkout may hold beside the code
        assert model_cache.fingerprint("tap", (urdf,)) == key, root


def _entries(cache, sizes: dict[str, int]) -> list:
    """Fake cached models of the given sizes, the first the oldest."""
    cache.mkdir(exist_ok=True)
    paths = []
    for i, (name, size) in enumerate(sizes.items()):
        path = cache / f"model-{name}.mjb"
        path.write_bytes(b"m" * size)
        os.utime(path, (1e9 + i, 1e9 + i))
        paths.append(path)
    return paths


def test_the_cache_is_bounded_in_size_and_per_variant_least_recently_used_first(cache, monkeypatch):
    monkeypatch.setattr(model_cache, "MAX_BYTES", 350)
    monkeypatch.setattr(model_cache, "KEEP", 2)
    old_tap, grasp, two_arms, tap, newer_tap, two_arms_left = _entries(cache, {
        "tap-a": 100, "grasp-a": 100, "two_arms-a": 100, "tap-b": 50, "tap-c": 50, "two_arms_left-a": 100})
    removed = model_cache.evict(cache)
    # newest first: two_arms_left (100), tap-c (50), tap-b (50; two taps now), two_arms (100): 300 bytes; grasp
    # would make 400; tap-a is a third tap.
    assert sorted(removed) == sorted([grasp, old_tap])
    assert {p.name for p in cache.glob("*.mjb")} == {p.name for p in (two_arms, tap, newer_tap, two_arms_left)}
    assert sum(p.stat().st_size for p in cache.glob("*.mjb")) <= model_cache.MAX_BYTES
    monkeypatch.setattr(model_cache, "MAX_BYTES", 10)  # the model just written stays, whatever its size and age
    model_cache.evict(cache, keep=tap)
    assert [p.name for p in cache.glob("*.mjb")] == [tap.name]


def test_a_new_model_evicts_the_least_recently_used_and_a_read_counts_as_use(cache, monkeypatch):
    def tiny(name):
        return lambda: mujoco.MjModel.from_xml_string(f'<mujoco model="{name}"><worldbody/></mujoco>')

    def never():
        raise AssertionError("compiled instead of read from the cache")

    model_cache.cached_model("tap", ("<robot name='a'/>",), tiny("a"))
    model_cache.cached_model("grasp", ("<robot name='b'/>",), tiny("b"))
    (a,), (b,) = cache.glob("model-tap-*.mjb"), cache.glob("model-grasp-*.mjb")
    os.utime(a, (1e9, 1e9))  # a is the older, then read: used last
    os.utime(b, (1e9 + 1, 1e9 + 1))
    model_cache.cached_model("tap", ("<robot name='a'/>",), never)
    assert a.stat().st_mtime > b.stat().st_mtime
    monkeypatch.setattr(model_cache, "MAX_BYTES", a.stat().st_size + b.stat().st_size + 10)
    model_cache.cached_model("two_arms", ("<robot name='c'/>",), tiny("c"))  # room for two of the three
    assert a.exists() and not b.exists() and len(list(cache.glob("*.mjb"))) == 2
