"""``spinectl draw``: the model drawing as PNG, PDF or SVG; errors as one line, nothing written."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
from matplotlib.image import imread

from spinectl.cli import main


def test_draw_writes_png_pdf_and_svg(tmp_path, capsys):
    """The optimum by default (--counter-torque), given PCSA, geometry only; each file real of its kind."""
    runs = [
        ["--E", "0.03", "--Lambda", "0.04", "--counter-torque", "--out", str(tmp_path / "a.png"), "--dpi", "80"],
        ["--E", "0", "--Lambda", "0.08", "--pcsa", "10,0,5", "--out", str(tmp_path / "b.pdf")],
        ["--E", "0.08", "--geometry-only", "--preset", "wagner2012", "--out", str(tmp_path / "c.svg")],
    ]
    for argv in runs:
        assert main(["draw", *argv]) == 0
    assert capsys.readouterr().out.split() == [str(tmp_path / n) for n in ("a.png", "b.pdf", "c.svg")]
    image = imread(tmp_path / "a.png")
    assert image.shape[1] == round(5.6 * 80) and image.std() > 0.05  # drawing.FIGURE_SIZE at 80 dpi
    assert len(np.unique(image.reshape(-1, image.shape[-1]), axis=0)) > 20
    assert (tmp_path / "b.pdf").read_bytes().startswith(b"%PDF-")
    assert ET.parse(tmp_path / "c.svg").getroot().tag.endswith("svg")


def test_draw_errors_are_one_line_and_write_nothing(tmp_path, capsys):
    cases = {
        ("--out", str(tmp_path / "x.txt")): "--out: must end in .png, .pdf or .svg",
        (
            "--geometry-only",
            "--counter-torque",
            "--out",
            str(tmp_path / "x.png"),
        ): "counter_torque: needs an activation",
        ("--pcsa", "1,2", "--out", str(tmp_path / "x.png")): "pcsa",
        ("--E", "0.5", "--out", str(tmp_path / "x.png")): "E",
        ("--dpi", "0", "--pcsa", "1,1,1", "--out", str(tmp_path / "x.png")): "--dpi",
    }
    for argv, message in cases.items():
        assert main(["draw", *argv]) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_draw_never_replaces_its_own_config(tmp_path, capsys):
    """``--out`` naming the ``--config`` file (whatever its suffix): one line, exit 2, the config intact."""
    config = tmp_path / "c.svg"
    config.write_text('preset = "default"\n', encoding="utf-8")
    code = main(["draw", "--E", "0.03", "--Lambda", "0.04", "--config", str(config), "--out", str(config)])
    assert code == 2 and "is the same file as --config" in capsys.readouterr().err
    assert config.read_text(encoding="utf-8") == 'preset = "default"\n'


def test_a_non_ascii_output_name_on_an_ascii_terminal(tmp_path):
    """``PYTHONIOENCODING=ascii``: the file Λ.png is written and its name printed escaped, exit 0."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    env = {**os.environ, "PYTHONIOENCODING": "ascii", "PYTHONPATH": str(root)}
    out = tmp_path / "Λ.png"
    command = [sys.executable, "-m", "spinectl", "draw", "--E", "0.03", "--Lambda", "0.04", "--geometry-only"]
    done = subprocess.run([*command, "--out", str(out)], capture_output=True, text=True, env=env, check=False)
    assert done.returncode == 0, done.stderr
    assert out.exists() and "\\u039b.png" in done.stdout
