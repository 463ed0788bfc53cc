"""Every ``--json`` document is strict JSON: ``null`` plus a ``<key>_reason`` for a missing number (docs/cli.md)."""

from __future__ import annotations

import json
import math

import pytest

from spinectl import jsondoc
from spinectl.cli import main


def strict_loads(text: str):
    """``json.loads`` as a strict parser reads JSON: the bare words NaN, Infinity, -Infinity are errors."""

    def refuse(word):
        raise ValueError(f"not JSON: {word}")

    return json.loads(text, parse_constant=refuse)


def _walk(document, path=""):
    """Every (path, key, value) of the dicts in ``document``."""
    if isinstance(document, dict):
        for key, value in document.items():
            yield path, key, value
            yield from _walk(value, f"{path}.{key}")
    elif isinstance(document, list):
        for k, item in enumerate(document):
            yield from _walk(item, f"{path}[{k}]")


def _flat(value):
    """The leaves of a nested list."""
    if isinstance(value, list):
        for item in value:
            yield from _flat(item)
    else:
        yield value


def _reasons_are_words(document) -> int:
    """Every ``<key>_reason`` holds words of :data:`spinectl.jsondoc.REASONS` where its value is null; the count."""
    count = 0
    for _, key, value in _walk(document):
        if isinstance(value, dict):
            for name, why in value.items():
                if name.endswith("_reason"):
                    number = value[name.removesuffix("_reason")]
                    pairs = (
                        list(zip(_flat(number), _flat(why), strict=True)) if isinstance(why, list) else [(number, why)]
                    )
                    assert all((n is None) == (w is not None) for n, w in pairs), (key, name)
                    assert all(w in jsondoc.REASONS for _, w in pairs if w is not None), (key, name)
                    count += 1
    return count


COMMANDS = {
    # point where segments are not self-stable, the PCSA given: stability writes the time constant "never returns"
    # and no LP minimum ("not computed")
    "stability": ["stability", "--E", "0.03", "--Lambda", "0.04", "--pcsa", "1,1,1"],
    # massless levels: a singular mass matrix, eigenvalues not computed (tests/cli/test_stability_cmd.py)
    "stability --coupled": ["stability", "--coupled", "--E", "0.03", "--set", "levels.mass=0"],
    "margins": ["margins", "--E", "0.03", "--Lambda", "0.04", "--activation", "1"],
    "margins --coupled": ["margins", "--coupled", "--E", "0.03", "--Lambda", "0.04", "--preset", "wagner2012"],
}


@pytest.mark.parametrize("name", list(COMMANDS))
def test_every_json_command_prints_strict_json(name, capsys):
    """No NaN or Infinity reaches the output (a strict parser reads it), and each null number says why."""
    assert main([*COMMANDS[name], "--json"]) == 0
    out = capsys.readouterr().out
    document = strict_loads(out)
    assert _reasons_are_words({"": document}) > 0  # each of these points has numbers without a finite value


def test_stability_and_margins_mark_a_segment_that_never_returns_alike(capsys):
    """The same unstable segment: stability's and margins's slowest time constant are both null, 'never_returns'
    (before: Infinity in stability, NaN in margins)."""
    argv = ["--E", "0.03", "--Lambda", "0.04", "--preset", "wagner2012", "--json"]
    assert main(["stability", "--pcsa", "1,1,1", *argv]) == 0
    stability = strict_loads(capsys.readouterr().out)
    assert not stability["all_self_stable"]
    assert stability["slowest_time_constant_s"] is None
    assert stability["slowest_time_constant_s_reason"] == "never_returns"
    assert stability["min_pcsa_cm2"] is None and stability["min_pcsa_cm2_reason"] == "not_computed"
    assert main(["margins", "--activation", "0.5", *argv]) == 0
    segments = strict_loads(capsys.readouterr().out)["segments"]
    unstable = [s for s in segments if not s["self_stable"]]
    assert unstable, "the point must have a segment that is not self-stable"
    assert all(s["slowest_time_constant_s"] is None for s in unstable)
    assert all(s["slowest_time_constant_s_reason"] == "never_returns" for s in unstable)


def test_coupled_margins_without_a_disk_margin_say_none(capsys):
    """wagner2012 at (3, 4) cm: the chain is unstable at 0.1 s (margin 0.16 ms, docs/chain.md), so it has no disk
    margin: null with 'none', as the table's 'none' (before: NaN in JSON, 'nan' in the table)."""
    argv = ["margins", "--coupled", "--E", "0.03", "--Lambda", "0.04", "--preset", "wagner2012"]
    assert main([*argv, "--json"]) == 0
    coupled = strict_loads(capsys.readouterr().out)["coupled"]
    assert coupled["stable_at_delay"] is False
    assert coupled["disk_margin"] is None and coupled["disk_margin_reason"] == "none"
    for joint in coupled["disk_loop_at_a_time"]:
        assert joint == {
            "disk_margin": None, "disk_margin_reason": "none",
            "disk_gain_margin": None, "disk_gain_margin_reason": "none",
            "disk_phase_margin_deg": None, "disk_phase_margin_deg_reason": "none",
        }  # fmt: skip
    assert main(argv) == 0
    table = capsys.readouterr().out
    rows = [line.split() for line in table.splitlines() if line.startswith(("L1L2 ", "L5S1 "))][-2:]
    assert all(row[-3:] == ["none", "none", "none"] for row in rows)
    assert "nan" not in table
    assert "PCSA [cm^2] (0.5 x the minimum stabilising per segment" in table
    assert "(minimum stabilising per segment)" not in table


def test_strict_keeps_finite_values_and_shapes_the_reasons_of_lists():
    """The convention itself: finite numbers untouched, a reason list shaped like its value."""
    document = {"a": 1.5, "b": math.inf, "c": [[0.0, math.nan], [1.0, 2.0]], "d": {"kp_min_Nm_per_rad": math.nan}}
    out = jsondoc.strict(document)
    assert out == {
        "a": 1.5,
        "b": None,
        "b_reason": "unbounded",
        "c": [[0.0, None], [1.0, 2.0]],
        "c_reason": [[None, "not_computed"], None],
        "d": {"kp_min_Nm_per_rad": None, "kp_min_Nm_per_rad_reason": "none"},
    }
    assert jsondoc.reason("x", -math.inf) == "-unbounded"
    strict_loads(jsondoc.dumps(document))
