"""``spinectl design``: the design question on the command line (the search itself: tests/reflex/test_design.py)."""

from __future__ import annotations

import json

import pytest

from spinectl import jsondoc
from spinectl.cli import main
from spinectl.cli._common import with_lordosis_angle
from spinectl.model import config
from spinectl.reflex.design import design

KEYS = ("activation", "segments", "chain", "delay_s", "activation_time_constant_s", "status")


def test_json_is_the_designs_dict_with_the_keys_for_scripts(capsys):
    """``--json`` prints Design.to_dict() with ``lordosis_angle_deg`` beside ``Lambda_m``:
    the keys scripts read, strict JSON (no NaN), each segment's and the
    chain's answer with its criterion."""
    argv = ["design", "--preset", "wagner2012", "--delay", "0.04", "--E", "0.03", "--Lambda", "0.04", "--json"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    model = config.set_parameters(config.load_preset("wagner2012"), {"reflex.delay": 0.04})
    assert out == jsondoc.dumps(with_lordosis_angle(design(model, 0.03, 0.04).to_dict(), model))
    doc = json.loads(out, parse_constant=lambda word: pytest.fail(f"{word} in strict JSON"))
    assert all(key in doc for key in KEYS) and doc["delay_s"] == 0.04
    assert all({"name", "activation", "pcsa_cm2", "delay_margin_s"} <= set(s) for s in doc["segments"])
    assert {"local_stiffness_Nm_per_rad", "activation", "delay_margin_s", "max_root_real_per_s"} <= set(doc["chain"])
    assert doc["criterion"].startswith("joint by joint") and doc["chain"]["criterion"].startswith("chain")


@pytest.mark.parametrize("delay", ["-0.1", "1e9", "nan"])
def test_a_negative_or_absurd_delay_is_one_line_exit_2(delay, capsys):
    """A delay outside [0, 10] s (reflex.delay's range) or not a number: one line on stderr, exit 2, no output."""
    assert main(["design", f"--delay={delay}"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "delay" in err
