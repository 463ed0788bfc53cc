"""``--lordosis-angle DEG`` wherever ``--Lambda`` is taken, and the study file's ``axes.lordosis_angle_deg``.

The second reading of every angle is the closed form of the natural cubic spline's end tangents,
written out here: theta = 2 atan(3 Lambda / L), so Lambda = L tan(theta / 2) / 3 (phi'(0) = 3/2;
docs/atlas.md, "Clinical geometry"), with L the preset's spine length.
"""

from __future__ import annotations

import json
import math
import types

import numpy as np
import pytest

from spinectl.cli import main
from spinectl.errors import ParameterError
from spinectl.landscape.study import files
from spinectl.model.config import load_config

ANGLE = 50.0


def _closed_form(angle: float) -> float:
    """Lambda [m] of a natural cubic spine line whose end tangents are ``angle`` [deg] apart."""
    geometry = load_config(None).geometry
    assert geometry.spline_bc == "natural"  # the closed form below is this end condition's
    return geometry.spine_length * math.tan(math.radians(angle) / 2.0) / 3.0


def _json(argv, capsys) -> dict:
    assert main([*argv, "--json"]) == 0, capsys.readouterr().err
    return json.loads(capsys.readouterr().out)


def _close(a, b, path="") -> None:
    """Two JSON documents equal, numbers to 1e-9 relative (Lambda a few ulp apart)."""
    if isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for key in a:
            _close(a[key], b[key], f"{path}.{key}")
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _close(x, y, f"{path}[{i}]")
    elif isinstance(a, float) and isinstance(b, float):
        assert a == pytest.approx(b, rel=1e-9, abs=1e-12), path
    else:
        assert a == b, path


def test_stability_angle_answers_as_its_lambda(capsys):
    """``stability --lordosis-angle 50`` is ``--Lambda`` of the closed form, to 1e-12 m, in the whole document;
    both documents carry ``lordosis_angle_deg`` = 50 beside ``Lambda_m``."""
    lam = _closed_form(ANGLE)
    by_angle = _json(["stability", "--E", "0.02", "--lordosis-angle", f"{ANGLE}"], capsys)
    by_lambda = _json(["stability", "--E", "0.02", "--Lambda", repr(lam)], capsys)
    assert abs(by_angle["Lambda_m"] - lam) < 1e-12
    keys = list(by_angle)
    assert keys[keys.index("Lambda_m") + 1] == "lordosis_angle_deg"
    assert by_angle["lordosis_angle_deg"] == pytest.approx(ANGLE, abs=1e-12)
    _close(by_angle, by_lambda)


class _Stop(Exception):
    """Raised by a stand-in library function once it has its arguments."""


def _recorder(seen: dict, stop: bool):
    """A stand-in for a command's library call: records (E, Lambda) and returns a stub result (or stops)."""

    def call(model, eccentricity, lordosis, *args, **kwargs):
        seen["E"], seen["Lambda"] = eccentricity, lordosis
        if stop:
            raise _Stop
        document = {"E_m": eccentricity, "Lambda_m": lordosis}
        return types.SimpleNamespace(to_dict=lambda *a, **k: dict(document), table=lambda *a, **k: "")

    return call


@pytest.mark.parametrize(
    ("command", "module", "name"),
    [
        (["margins"], "spinectl.reflex.chain_verdict", "margins_with_chain"),
        (["margins", "--coupled"], "spinectl.reflex.chain_margins", "coupled_margins"),
        (["design"], "spinectl.reflex.design", "answer"),
    ],
)
def test_reflex_commands_pass_the_angle_as_its_lambda(command, module, name, monkeypatch, capsys):
    """margins and design hand their library the closed form's Lambda (to 1e-12 m) for ``--lordosis-angle 50``,
    and their JSON gains ``lordosis_angle_deg`` = 50 beside ``Lambda_m``."""
    seen: dict = {}
    monkeypatch.setattr(f"{module}.{name}", _recorder(seen, stop=False))
    document = _json([*command, "--E", "0.02", "--lordosis-angle", f"{ANGLE}"], capsys)
    assert abs(seen["Lambda"] - _closed_form(ANGLE)) < 1e-12 and seen["E"] == 0.02
    assert list(document) == ["E_m", "Lambda_m", "lordosis_angle_deg"]
    assert document["lordosis_angle_deg"] == pytest.approx(ANGLE, abs=1e-12)


def test_draw_passes_the_angle_as_its_lambda(monkeypatch, tmp_path):
    """``draw --lordosis-angle 50`` draws at the closed form's Lambda (to 1e-12 m)."""
    seen: dict = {}
    monkeypatch.setattr("spinectl.paper.drawing.draw_model", _recorder(seen, stop=True))
    with pytest.raises(_Stop):
        main(["draw", "--lordosis-angle", f"{ANGLE}", "--out", str(tmp_path / "m.png")])
    assert abs(seen["Lambda"] - _closed_form(ANGLE)) < 1e-12


def test_sweep_angle_axis_is_even_in_degrees(monkeypatch, tmp_path):
    """``sweep --lordosis-angle 20:60:5``: the Lambda axis is the closed form of 20, 30, ..., 60 deg, to 1e-12 m."""
    seen: dict = {}
    monkeypatch.setattr("spinectl.landscape.sweep.write_sweep", _recorder(seen, stop=True))
    with pytest.raises(_Stop):
        main(["sweep", "--E", "0.01", "--lordosis-angle", "20:60:5", "--out", str(tmp_path / "s.nc")])
    expected = [_closed_form(a) for a in (20.0, 30.0, 40.0, 50.0, 60.0)]
    np.testing.assert_allclose(seen["Lambda"], expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize(
    ("command", "given", "says"),
    [
        (["stability"], ["--Lambda", "0.04", "--lordosis-angle", "50"], "not allowed with --Lambda"),
        (["margins"], ["--lordosis-angle", "200"], "strictly between -180 and 180 deg"),
        (["design"], ["--lordosis-angle", "170"], "deg, the modelled range of Lambda"),
        (["draw", "--out", "x.png"], ["--lordosis-angle", "-150"], "deg, the modelled range of Lambda"),
        (["sweep", "--out", "x.nc"], ["--lordosis-angle", "20:170:3"], "deg, the modelled range of Lambda"),
        (["sweep", "--out", "x.nc"], ["--Lambda", "0:0.08:3", "--lordosis-angle", "20:60:3"], "not allowed with"),
        (["sweep", "--out", "x.nc"], ["--lordosis-angle", "20:60"], "START:STOP:NUM in degrees"),
    ],
)
def test_angle_errors_are_one_line_exit_2(command, given, says, capsys, tmp_path, monkeypatch):
    """Both lordosis options at once, an angle outside (-180, 180) deg, or one beyond the modelled Lambda
    (the preset's 10 cm is 2 atan(3 x 0.1 / 0.176) = 119.2 deg): one line, exit 2, nothing written."""
    monkeypatch.chdir(tmp_path)
    assert main([*command, *given]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--lordosis-angle" in err and says in err, err
    assert not list(tmp_path.iterdir())


def _study(axes: str):
    return files.parse_study(f'[study]\npreset = "wagner2012"\n[axes]\nE = [0.01]\n{axes}\n')


def test_study_angle_axis_is_its_lambda():
    """``axes.lordosis_angle_deg = { start = 20, stop = 60, num = 5 }`` is the closed form's Lambda, to 1e-12 m."""
    study = _study("lordosis_angle_deg = { start = 20.0, stop = 60.0, num = 5 }")
    expected = [_closed_form(a) for a in (20.0, 30.0, 40.0, 50.0, 60.0)]
    np.testing.assert_allclose(study.lordosis, expected, rtol=0, atol=1e-12)
    assert not study.axes  # the angle is the grid's axis, not a parameter axis


@pytest.mark.parametrize(
    ("axes", "says"),
    [
        ("Lambda = [0.01]\nlordosis_angle_deg = [50.0]", "both give the lordosis"),
        ("lordosis_angle_deg = [50.0, 170.0]", "the modelled range of Lambda"),
        ("lordosis_angle_deg = [180.0]", "strictly between -180 and 180"),
    ],
)
def test_study_angle_axis_errors(axes, says):
    """The study file's angle axis refuses what ``--lordosis-angle`` refuses, naming ``axes.lordosis_angle_deg``."""
    with pytest.raises(ParameterError, match=says) as caught:
        _study(axes)
    assert caught.value.field == "axes.lordosis_angle_deg"


@pytest.mark.parametrize(("typed", "hint"), [("0.7", "give 40.107"), ("-1.2", "give 68.755")])
def test_an_angle_in_radians_gets_a_hint_and_is_analysed_as_given(typed, hint, capsys):
    """0.7 (radians typed for degrees) is a valid, nearly straight spine: analysed as 0.7 deg, with one line
    on stderr naming the option and the degrees meant (0.7 rad = 0.7 * 180 / pi = 40.107 deg)."""
    argv = ["stability", "--E", "0.03", "--pcsa", "10,10,10", "--json"]
    assert main([*argv, "--lordosis-angle", typed]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["Lambda_m"] == pytest.approx(_closed_form(float(typed)), rel=1e-12)
    assert err.count("\n") == 1 and err.startswith("spinectl: warning: --lordosis-angle: ") and hint in err


@pytest.mark.parametrize("typed", ["0", "5", str(ANGLE)])
def test_a_plausible_angle_or_zero_is_silent(typed, capsys):
    assert main(["stability", "--E", "0.03", "--pcsa", "10,10,10", "--lordosis-angle", typed]) == 0
    assert capsys.readouterr().err == ""
