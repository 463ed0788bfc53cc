"""The cache of compiled MuJoCo models: the same chains as a fresh compile, its key, corrupt files, no folder."""

from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
import types

import numpy as np
import pytest

pytest.importorskip("mujoco", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")

MJCF = """<mujoco model="tiny">
  <asset><mesh name="box" file="box.obj"/></asset>
  <worldbody>
    <body name="link" pos="0 0 1">
      <joint name="hinge" type="hinge" axis="0 1 0" stiffness="{stiffness}"/>
      <geom type="mesh" mesh="box" density="1000"/>
    </body>
  </worldbody>
</mujoco>
"""
"""A one-joint model whose link's inertia MuJoCo computes from a mesh file (so that the mesh's bytes matter)."""


def cube(x: float) -> str:
    """A cube of half-edge ``x`` [m] about its centre, in OBJ (MuJoCo writes the same MJCF for every ``x``)."""
    corners = "".join(f"v {x * i} {x * j} {x * k}\n" for i in (-1, 1) for j in (-1, 1) for k in (-1, 1))
    return corners + "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n"


@pytest.fixture
def folder(tmp_path, monkeypatch):
    """An empty cache folder, named by ``$SPINECTL_CACHE_DIR``."""
    cache = tmp_path / "cache"
    monkeypatch.setenv("SPINECTL_CACHE_DIR", str(cache))
    return cache


def tiny(tmp_path, stiffness=1.0, x=0.1):
    """Write the tiny model and its mesh into ``tmp_path`` (made if missing); return the MJCF's path."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / "box.obj").write_text(cube(x))
    path = tmp_path / "tiny.xml"
    path.write_text(MJCF.format(stiffness=stiffness))
    return path


def binary(model) -> bytes:
    """MuJoCo's whole serialisation of a compiled model (every array, every name)."""
    import mujoco

    out = np.empty(mujoco.mj_sizeModel(model), np.uint8)
    mujoco.mj_saveModel(model, None, out)
    return out.tobytes()


def test_cached_myotorso_gives_the_same_chains_bit_for_bit(folder):
    """MyoTorso read from the cache and compiled anew: identical K_0, every K_i, D, M (bit for bit), classes, SHA-256.

    The second load must come from the cache file (it is the only one written), and its chains are
    compared with ``==`` against a fresh compile's, not within a tolerance.
    """
    pytest.importorskip("myo_sim", reason="needs the anatomy extra: pip install 'spinectl[anatomy]'")
    from spinectl import anatomy
    from spinectl.anatomy import cache

    fresh = anatomy.load("myotorso", cache=False)
    assert not folder.exists()  # cache=False writes nothing
    anatomy.load("myotorso")  # compiles, writes the cache
    key = cache.builtin_key("myotorso", __import__("myo_sim"))
    assert cache.read(key) is not None
    cached = anatomy.load("myotorso")
    assert binary(cached.engine.model) == binary(fresh.engine.model)
    assert (cached.muscles, cached.classes, cached.engine.sha256) == (fresh.muscles, fresh.classes, fresh.engine.sha256)
    chains = (torso.chains("sagittal", joint_stiffness=50.0) for torso in (cached, fresh))
    for ours, theirs in zip(*chains, strict=True):
        arrays = [f.name for f in dataclasses.fields(ours) if isinstance(getattr(ours, f.name), np.ndarray)]
        assert {"mass_matrix", "stiffness_offset"} <= set(arrays) or {"mass", "stiffness_offset"} <= set(arrays)
        for name in arrays:
            np.testing.assert_array_equal(getattr(ours, name), getattr(theirs, name), err_msg=name)


def test_a_corrupt_cache_file_is_ignored_and_rebuilt(folder, tmp_path, caplog, capfd):
    """A cache file with one byte changed, one truncated, a header of garbage: each load equals a fresh compile.

    One byte flipped in the ``.mjb`` still parses as a model (MuJoCo checks sizes, not values), so only
    the header's checksum can refuse it; afterwards the pair is rewritten and matches again. No
    traceback, nothing printed (a truncated file reaching MuJoCo would print its warning).
    """
    from spinectl.anatomy import cache
    from spinectl.anatomy.engine import load_engine

    path = tiny(tmp_path)
    reference = binary(load_engine(path, cache=False).model)
    load_engine(path)
    (mjb,) = folder.glob("*.mjb")
    header = mjb.with_suffix(".json")
    good = mjb.read_bytes()
    corruptions = [
        (mjb, good[:-1] + bytes([good[-1] ^ 0xFF])),
        (mjb, good[: len(good) // 2]),
        (header, b"{not json"),
        (header, json.dumps({"key": "another", "mjb_sha256": hashlib.sha256(good).hexdigest()}).encode()),
    ]
    caplog.set_level(logging.DEBUG, logger="spinectl.anatomy.cache")
    for target, content in corruptions:
        keep = header.read_bytes()
        target.write_bytes(content)
        if target == header:
            assert cache.read(mjb.stem) is None
        engine = load_engine(path)
        assert binary(engine.model) == reference
        assert mjb.read_bytes() == good and header.read_bytes() == keep  # rebuilt
    assert "ignoring the compiled-model cache" in caplog.text
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_the_key_changes_with_the_model_its_mesh_and_the_versions(tmp_path, monkeypatch):
    """A different stiffness in the MJCF, a different mesh file, another MuJoCo version: three other keys.

    The bigger cube changes the compiled link's mass and inertia without changing one byte of the
    MJCF (checked), so the key must read the asset's bytes; the same inputs give the same key.
    """
    import mujoco

    from spinectl.anatomy.cache import file_key

    def key(folder, **kwargs):
        return file_key(mujoco.MjSpec.from_file(str(tiny(folder, **kwargs))))

    base = key(tmp_path / "a")
    assert key(tmp_path / "b") == base
    small, big = (mujoco.MjSpec.from_file(str(tiny(tmp_path / f, x=x))) for f, x in (("a", 0.1), ("d", 0.2)))
    assert small.to_xml() == big.to_xml() and small.compile().body_mass[1] != big.compile().body_mass[1]
    assert key(tmp_path / "c", stiffness=2.0) != base
    assert key(tmp_path / "d", x=0.2) != base
    monkeypatch.setattr(mujoco, "__version__", mujoco.__version__ + ".other")
    assert key(tmp_path / "a") != base


def test_the_builtin_key_reads_the_package_sources_and_version(tmp_path):
    """A built-in model's key changes with its package's version, a source file's bytes, a mesh's size."""
    from spinectl.anatomy.cache import builtin_key

    (tmp_path / "__init__.py").write_text("")
    (tmp_path / "model.xml").write_text("<mujoco/>")
    (tmp_path / "mesh.stl").write_bytes(b"12")
    package = types.SimpleNamespace(__file__=str(tmp_path / "__init__.py"), __name__="fake", __version__="1.0")
    base = builtin_key("fake", package)
    assert builtin_key("fake", package) == base
    package.__version__ = "1.1"
    assert builtin_key("fake", package) != base
    package.__version__ = "1.0"
    (tmp_path / "model.xml").write_text("<mujoco model='x'/>")
    edited = builtin_key("fake", package)
    assert edited != base
    (tmp_path / "mesh.stl").write_bytes(b"123")
    assert builtin_key("fake", package) != edited


def test_an_unwritable_cache_folder_still_loads(tmp_path, monkeypatch, caplog):
    """A cache folder that cannot be made (under a regular file: refused even to root) loads, one debug line."""
    from spinectl.anatomy.engine import load_engine

    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("SPINECTL_CACHE_DIR", str(blocker / "cache"))
    path = tiny(tmp_path)
    caplog.set_level(logging.DEBUG, logger="spinectl.anatomy.cache")
    engine = load_engine(path)
    assert binary(engine.model) == binary(load_engine(path, cache=False).model)
    assert [r.levelno for r in caplog.records] == [logging.DEBUG]


def test_the_cache_folder_follows_the_environment(tmp_path, monkeypatch):
    """$SPINECTL_CACHE_DIR first, then $XDG_CACHE_HOME/spinectl, then ~/.cache/spinectl."""
    from spinectl.anatomy.cache import cache_dir

    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.delenv("SPINECTL_CACHE_DIR", raising=False)
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    assert cache_dir() == tmp_path / "home" / ".cache" / "spinectl"
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_dir() == tmp_path / "xdg" / "spinectl"
    monkeypatch.setenv("SPINECTL_CACHE_DIR", str(tmp_path / "mine"))
    assert cache_dir() == tmp_path / "mine"


def test_no_cache_on_the_command_line_writes_nothing(folder, tmp_path, capsys):
    """``spinectl anatomy FILE --no-cache`` leaves the cache folder unmade; without it the compiled model is cached.

    The file has no mapping, so both runs end in the same one-line error (exit 2) after loading.
    """
    from spinectl.cli import main

    path = tiny(tmp_path)
    assert main(["anatomy", str(path), "--no-cache"]) == 2
    assert not folder.exists()
    assert main(["anatomy", str(path)]) == 2
    assert len(list(folder.glob("*.mjb"))) == 1
    assert capsys.readouterr().err.count("\n") == 2


@pytest.mark.parametrize("cached", [True, False], ids=["cache", "no-cache"])
@pytest.mark.parametrize(
    ("fault", "said"),
    [
        ("missing mesh", "MuJoCo cannot compile"),  # before, with the cache: a ValueError traceback
        ("nan mass", "Element name 'link', id 1"),  # MuJoCo's second line, and its NaN warning
        ("nan stiffness", "<joint> 'hinge': stiffness is nan (MuJoCo's jnt_stiffness)"),  # before: LinearChain's
        ("inf stiffness", "<joint> 'hinge': stiffness is inf"),
        ("bad keyword", "invalid keyword: 'bogus'; Element 'joint', line 5"),  # before: cut at the first line
    ],
)
def test_an_mjcf_that_mujoco_refuses_is_one_line_with_its_reason(
    folder, tmp_path, capfd, monkeypatch, fault, said, cached
):
    """The tiny model with one fault, loaded with and without the compiled-model cache: `spinectl anatomy` says
    MuJoCo's reason (all its lines joined) or names the element and attribute of a non-finite number, one line on
    stderr, exit 2; nothing on stdout, no MUJOCO_LOG.TXT where it runs (MuJoCo's own warning handler writes both)."""
    from spinectl.cli import main

    monkeypatch.chdir(tmp_path)
    path = tiny(tmp_path / "model")
    text = path.read_text()
    if fault == "missing mesh":
        (tmp_path / "model" / "box.obj").unlink()
    elif fault == "nan mass":
        text = text.replace(
            '<joint name="hinge"', '<inertial pos="0 0 0" mass="nan" diaginertia="1 1 1"/><joint name="hinge"'
        )
    elif fault == "bad keyword":
        text = text.replace('type="hinge"', 'type="bogus"')
    else:
        text = text.replace('stiffness="1.0"', f'stiffness="{fault.split()[0]}"')
    path.write_text(text)
    argv = ["anatomy", str(path)] + ([] if cached else ["--no-cache"])
    assert main(argv) == 2
    out, err = capfd.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith("spinectl: error: model: ") and said in err, err
    if fault.startswith("nan"):
        assert "XML contains a 'NaN'" in err
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def test_a_nan_is_not_the_cached_model_without_it(folder, tmp_path):
    """MuJoCo writes the spec of `stiffness="nan"` as if the attribute were absent: the key reads the file's own
    bytes too, so the NaN file is not given the clean file's compiled model from the cache (before: it was, and the
    NaN went unnoticed)."""
    from spinectl.anatomy.engine import load_engine
    from spinectl.errors import ParameterError

    clean = tiny(tmp_path / "a", stiffness=0.0)
    assert load_engine(clean).model.jnt_stiffness[0] == 0.0  # now cached
    faulty = tiny(tmp_path / "a", stiffness="nan")
    with pytest.raises(ParameterError, match="stiffness is nan"):
        load_engine(faulty)
