"""Unit conversions at the edges: what the console prints (spinectl.units)."""

from __future__ import annotations


def test_export_prints_its_position_in_cm_as_every_command():
    """`spinectl export` printed "E = 0.03 m, Lambda = 0.04 m" where every other command prints cm: it prints
    units.position_text, cm; a point off the whole centimetre keeps its digits (2.5 cm, 0.1 cm)."""
    from spinectl.units import position_text

    assert position_text(0.03, 0.04) == "E = 3 cm, Lambda = 4 cm"
    assert position_text(0.025, 0.001) == "E = 2.5 cm, Lambda = 0.1 cm"


def test_the_export_command_line_says_cm(tmp_path, capsys):
    """The MJCF export (no OpenSim needed): its first line gives E and Lambda in cm (units.position_text)."""
    from spinectl.cli import main
    from spinectl.units import position_text

    out = tmp_path / "m.xml"
    assert main(["export", "--E", "0.025", "--Lambda", "0.04", "--out", str(out)]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert first.endswith(f"(mjcf): {position_text(0.025, 0.04)}") and first.endswith("E = 2.5 cm, Lambda = 4 cm")
