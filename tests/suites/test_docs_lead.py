"""README.md and docs/reproduction.md lead with the paper's main claim, as report.md does, not with a count.

The numbers docs/reproduction.md quotes are the ``{measured}`` role's (docs/_ext/spinectl_docs/reproduction.py),
the documented verdicts' values that tests/paper/test_verdicts.py checks against a fresh measurement.
"""

from __future__ import annotations

import sys
from pathlib import Path

from spinectl.paper import verdicts

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "docs" / "_ext"))
from spinectl_docs import MEASURED_VALUES, reproduction, values  # noqa: E402


def _in_short(text: str) -> str:
    """docs/reproduction.md's summary paragraph, from 'In short' to the blank line."""
    start = text.index("In short")
    return text[start : text.index("\n\n", start)]


def test_reproduction_page_leads_with_the_claim_in_generated_numbers():
    """The summary states the claim before the landmark count, each number through {measured}, none typed."""
    summary = _in_short((ROOT / "docs" / "reproduction.md").read_text(encoding="utf-8"))
    claim, count = summary.index("main claim"), summary.index("{measured}`reproduction.agreeing`")
    assert claim < count
    for name in ("claim", "optimum_lordosis", "ct_optimum"):
        assert f"{{measured}}`reproduction.{name}`" in summary
    assert "11 of" not in summary and "3.8 cm" not in summary and "28.4" not in summary


def test_the_reproduction_values_are_the_documented_verdicts():
    """The role's values are those of spinectl.paper.verdicts (the landmark table on the same page): the claim's
    two landmarks' values, 'reproduced' only when both are, and the count of reproduced landmarks of all."""
    assert reproduction in MEASURED_VALUES
    marks = verdicts.VERDICTS
    assert values.text_of("reproduction.optimum_lordosis") == verdicts.format_number(marks["optimum_lordosis"].value)
    assert values.text_of("reproduction.ct_optimum") == verdicts.format_number(marks["ct_optimum"].value)
    both = {marks["optimum_lordosis"].verdict, marks["ct_optimum"].verdict} == {verdicts.REPRODUCED}
    assert values.text_of("reproduction.claim") == ("reproduced" if both else "not reproduced")
    agreeing = sum(v.verdict == verdicts.REPRODUCED for v in marks.values())
    assert values.text_of("reproduction.agreeing") == f"{agreeing} of {len(marks)}"


def test_the_readme_leads_with_the_claim_not_a_count():
    """README.md says the paper's main claim is reproduced where it introduces report.md, and types no count."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "the paper's main claim is reproduced" in readme.replace("\n", " ")
    assert "of 22 landmarks" not in readme


def test_interchange_page_generates_its_growth_rates_and_names_opensims_linearisation():
    """docs/interchange.md: no 'OpenSim has no linearisation of its own' beside an export that prints OpenSim's own
    linearisation; the benchmark's and the re-import's growth rates are {measured} values (typed, they went stale:
    8.3 1/s where the export grows at 3.47 since the local muscles damp; 71.0 beside a table of 74.06), and the new
    value is the largest growing real part of OpenSim's own linearisation of the Millard export with local
    stiffness (spinectl.anatomy.interchange.opensim_eigenvalues, called here on the export)."""
    import numpy as np
    import pytest

    pytest.importorskip("opensim", reason="OpenSim is not installed")
    from spinectl_docs import interchange

    from spinectl.anatomy.interchange import opensim_eigenvalues

    page = (ROOT / "docs" / "interchange.md").read_text(encoding="utf-8")
    assert "no linearisation of its own" not in page and "OpenSim's own linearisation" in page
    for name in ("millard_local_fastest", "millard_fastest", "fastest"):
        assert f"{{measured}}`interchange.{name}`" in page
    path, solution = interchange.exported("osim", "millard", True)
    real = np.real(opensim_eigenvalues(path, solution.model.geometry.cor_names))
    assert values.text_of("interchange.millard_local_fastest") == f"{real.max():.2f}" and real.max() > 0
