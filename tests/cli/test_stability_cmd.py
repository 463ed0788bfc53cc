"""``spinectl stability --coupled``: the chain's document and table (docs/chain.md)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from spinectl import jsondoc
from spinectl.cli import main
from spinectl.model import config
from spinectl.model.clinical import with_lordosis_angle
from spinectl.optimise.coupled import coupled_stability_at


def test_coupled_json_is_the_results_dict(capsys):
    """--coupled --json prints CoupledStability.to_dict of the library call, with
    ``lordosis_angle_deg`` (values: tests/optimise)."""
    argv = ["stability", "--coupled", "--E", "0.03", "--Lambda", "0.04", "--preset", "wagner2012", "--json"]
    assert main(argv) == 0
    printed = json.loads(capsys.readouterr().out)
    model = config.load_preset("wagner2012")
    expected = coupled_stability_at(model, 0.03, 0.04).to_dict(model, pcsa_source="min_pcsa")
    assert printed == json.loads(jsondoc.dumps(with_lordosis_angle(expected, model)))
    assert printed["coupled"]["self_stable"] is False and printed["coupled"]["stable_with_local"] is True


def test_coupled_table_with_a_given_pcsa(capsys):
    """--pcsa is the global activation; the table names the matrices and the verdicts."""
    assert main(["stability", "--coupled", "--pcsa", "10,10,10", "--K", "15", "--preset", "default"]) == 0
    out = capsys.readouterr().out
    assert "mass M [kg m^2]" in out and "static margin" in out and "least local stiffness" in out
    model = config.set_parameter(config.load_preset("default"), "passive.stiffness", 15.0)
    result = coupled_stability_at(model, 0.0, 0.0, np.full(3, 10e-4))
    assert f"static margin (smallest eigenvalue of -K_chain) = {result.margin:.3f} N m/rad" in out
    # the chain's stiffness matrix is not the header's passive stiffness K (15 here), which is a part of it: the
    # matrix's title names it apart, and the local stiffness says where it adds
    assert "K = 15 N m/rad" in out.splitlines()[0]
    assert "stiffness matrix K_chain = dtau/dq [N m/rad]: global muscles, gravity and the passive stiffness" in out
    assert "least local stiffness added to the diagonal of -K_chain [N m/rad] (beside the passive K)" in out


def test_massless_levels_leave_the_eigenvalues_undefined(tmp_path, capsys):
    """levels.mass = 0: M = m J'J has rank 2 (1 at E = 0, the CoRs right below the mass), so no
    eigenvalues (NaN, not stable); the statics stand."""
    path = tmp_path / "m.toml"
    path.write_text("[levels]\nmass = 0.0\n")
    assert main(["stability", "--coupled", "--config", str(path)]) == 0
    assert "eigenvalues undefined, the mass matrix is singular" in capsys.readouterr().out
    assert main(["stability", "--coupled", "--config", str(path), "--E", "0.03", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)["coupled"]
    assert np.all(np.array(document["eigenvalues"]) == None) and document["self_stable"] is False  # noqa: E711
    assert np.all(np.array(document["eigenvalues_reason"]) == "not_computed")
    assert np.linalg.matrix_rank(np.array(document["mass_matrix_kgm2"])) == 2
    assert document["margin_Nm_per_rad"] < 0  # the static analysis does not need M


def test_no_stabilising_activation_names_the_option_on_the_command_line(tmp_path, capsys):
    """The library's message names its argument pcsa; the CLI's names --pcsa, in cm² as the option takes it."""
    config = tmp_path / "tiny.toml"
    config.write_text("[optimisation]\npcsa_max = 1e-6\n")
    assert main(["stability", "--E", "0", "--Lambda", "0", "--config", str(config)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no activation stabilises every segment" in err
    assert err.rstrip().endswith("give the PCSA with --pcsa [cm2]")


def test_coupled_verdicts_name_the_chain_criterion(capsys):
    """stability --coupled judges the whole chain, every CoR free (docs/chain.md): the JSON says so
    in ``coupled.criterion`` and each verdict line of the table starts with it (5 CoRs in default)."""
    name = "chain (all 5 CoRs free)"
    assert main(["stability", "--coupled", "--E", "0.03", "--Lambda", "0.04", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["coupled"]["criterion"] == name
    assert main(["stability", "--coupled", "--E", "0.03", "--Lambda", "0.04"]) == 0
    lines = capsys.readouterr().out.splitlines()
    verdicts = [line for line in lines if "stable" in line.lower()]
    assert len(verdicts) == 3 and all(line.startswith(f"{name}: ") for line in verdicts)


def test_coupled_table_prints_real_eigenvalues_as_real_numbers(capsys):
    """The chain's eigenvalues at E = 3 cm, Lambda = 4 cm (wagner2012) are all real (LAPACK returns an exact 0
    imaginary part for a real root of the real 10 x 10 state matrix): printed as reals, never ``68.321+0.000j``."""
    assert main(["stability", "--coupled", "--E", "0.03", "--Lambda", "0.04", "--preset", "wagner2012"]) == 0
    out = capsys.readouterr().out
    model = config.load_preset("wagner2012")
    result = coupled_stability_at(model, 0.03, 0.04)
    assert np.all(result.eigenvalues.imag == 0)  # the premise, so the assertion below can fail
    line = next(row for row in out.splitlines() if row.startswith("eigenvalues [1/s]: "))
    assert "j" not in line and line.endswith(", ".join(f"{z.real:.3f}" for z in result.eigenvalues))
    assert "+0.000j" not in out


def test_a_complex_eigenvalue_keeps_its_imaginary_part():
    from spinectl.model.stability import eigenvalue_text

    assert (
        eigenvalue_text(complex(-3.6531, 1.2)) == "-3.653+1.200j" and eigenvalue_text(complex(68.3214, 0)) == "68.321"
    )


def test_the_table_says_the_sign_of_s_and_d(capsys):
    """eq. 1 (theta phi'' = S phi + D phi') makes a restoring S and a damping D negative; the table says so
    right below its rows, where spinectl anatomy's -K_jj column is > 0 restoring."""
    from spinectl.model.stability import SIGN_NOTE

    assert main(["stability", "--E", "0.03", "--Lambda", "0.04", "--pcsa", "10,10,10"]) == 0
    lines = capsys.readouterr().out.splitlines()
    last_row = max(i for i, line in enumerate(lines) if line.startswith("L5S1"))
    assert lines[last_row + 1] == SIGN_NOTE and "S < 0 restores" in SIGN_NOTE and "D < 0 damps" in SIGN_NOTE


def test_contributions_say_which_pair_stabilises_each_cor_and_the_chain(capsys):
    """spinectl stability --contributions: each pair's part of each CoR's -K_jj, whose sum with the passive and
    gravity terms is the table's own joint stiffness (spinectl.model.chain.linear_chain at the same PCSA), and of
    the chain's least eigenvalue; in the table and the JSON (variant: a given PCSA, --json)."""
    from spinectl.model.chain import linear_chain

    assert main(["stability", "--E", "0.03", "--Lambda", "0.04", "--preset", "wagner2012", "--contributions"]) == 0
    assert "each pair's part of each CoR's stiffness" in capsys.readouterr().out
    args = ["stability", "--E", "0.01", "--Lambda", "0.02", "--pcsa", "2,8,4", "--preset", "wagner2012"]
    assert main([*args, "--contributions", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)["contributions"]
    chain = linear_chain(config.load_preset("wagner2012"), 0.01, 0.02)
    muscles = -np.diag(chain.stiffness([2.0, 8.0, 4.0])) + np.diag(chain.stiffness_offset)
    np.testing.assert_allclose(np.sum(doc["cor_share_Nm_per_rad"], axis=0), muscles, rtol=1e-10)
    assert doc["pairs"] == ["straight", "oblique_outer", "oblique_inner"] and len(doc["cor_stabilised_most_by"]) == 5


@pytest.mark.parametrize("argv", [["--preset", "wagner2012"], ["--preset", "default", "--K", "15", "--E", "0.02"]])
def test_coupled_damping_matrix_says_its_sign(argv, capsys):
    """stability --coupled prints D with every diagonal entry negative (the muscles damp): its title says which sign
    damps, as the per-segment table does ('D < 0 damps'); the issue's default and a variant (default, K 15, E 2 cm)."""
    assert main(["stability", "--coupled", *argv]) == 0
    lines = capsys.readouterr().out.splitlines()
    title = next(line for line in lines if line.startswith("damping D [N m s/rad]"))
    assert "D < 0 damps" in title
    first_row = lines[lines.index(title) + 2].split()
    assert float(first_row[1]) < 0  # the diagonal entry the note describes
