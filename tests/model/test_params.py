"""Plausible ranges of the model's lengths and forces: a unit slip is refused with its hint (docs/robustness.md)."""

from __future__ import annotations

import dataclasses

import pytest

from spinectl.errors import ParameterError
from spinectl.model import config
from spinectl.model.params import Body, Fibre, Geometry, Local, Model, MusclePair


@pytest.mark.parametrize(
    ("build", "message"),
    [
        # the paper's 326 mm typed as 32.6 cm: 32.6 m, a hundred times the trunk
        (
            lambda: Body(mass_height=32.6),
            "mass_height: must be at most 1 m, the modelled trunk's scale (got 32.6); "
            "lengths are in metres: if you meant 32.6 cm, give 0.326",
        ),
        (lambda: Geometry(spine_length=17.6), "spine_length: must be at most 1 m"),
        (lambda: MusclePair(upper=(12.0, 24.0)), "upper: must be at most 1 m in size"),
        (lambda: Local(lever_arm=7.0), "lever_arm: must be at most 1 m"),
        # the paper's 25 N/cm^2 typed without the conversion to N/m^2 (x 1e4)
        (
            lambda: Fibre(specific_tension=25.0),
            "specific_tension: must be in [10000, 1e+07] N/m^2, around reported human values (2-137 N/cm^2) "
            "(got 25); if you meant 25 N/cm^2, give 250000",
        ),
        (lambda: Fibre(specific_tension=250.0), "if you meant 250 kPa, give 250000"),
        (
            lambda: Body(gravity=981.0),
            "gravity: must be at most 30 m/s^2 (got 981); if you meant 981 cm/s^2, give 9.81",
        ),
    ],
)
def test_unit_slips_are_refused_with_their_hint(build, message):
    with pytest.raises(ParameterError) as err:
        build()
    assert message in str(err.value)


def test_the_presets_and_the_edges_of_the_ranges_are_accepted():
    for name in ("default", "wagner2012", "wagner2012_mass_free"):
        config.load_preset(name)
    Fibre(specific_tension=1e4)
    Fibre(specific_tension=1e7)
    Body(mass_height=1.0, gravity=30.0)


def test_the_cli_refuses_a_mass_height_in_cm(tmp_path, capsys):
    """The newcomer's case: the message names the field and the slip, not a PCSA the user never gave."""
    from spinectl.cli import main

    path = tmp_path / "m.toml"
    path.write_text("[body]\nmass_height = 32.6\n")
    for extra in (["--set", "body.mass_height=32.6"], ["--config", str(path)]):
        assert main(["stability", "--E", "0.03", "--Lambda", "0.04", *extra]) == 2
        err = capsys.readouterr().err
        assert "body.mass_height: must be at most 1 m" in err and "give 0.326" in err and "pcsa" not in err


def test_model_level_check_still_names_the_top_cor():
    with pytest.raises(ParameterError, match="body.mass_height: must lie above the top centre of rotation"):
        Model(body=dataclasses.replace(Body(), mass_height=0.1))


def _pairs(count: int, fibres: int = 5) -> tuple[MusclePair, ...]:
    base = MusclePair()
    return tuple(dataclasses.replace(base, name=f"p{i}", fibres=fibres) for i in range(count))


def test_the_number_of_pairs_cors_and_fibre_terms_is_bounded():
    """A model of many pairs or CoRs took the whole machine (100 pairs: 13 s a point) or aborted in native
    code; each count has a documented bound (params.MAX_MUSCLE_PAIRS, MAX_CORS, MAX_FIBRE_TERMS), checked
    before the pairwise checks, and the bounds themselves are accepted."""
    from spinectl.model import params

    Model(muscles=_pairs(params.MAX_MUSCLE_PAIRS))
    with pytest.raises(ParameterError, match=f"must list at most {params.MAX_MUSCLE_PAIRS} pairs") as info:
        Model(muscles=_pairs(params.MAX_MUSCLE_PAIRS + 1))
    assert info.value.field == "muscles"
    top = Model().body.mass_height
    heights = tuple(0.15 * (1 - i / params.MAX_CORS) for i in range(params.MAX_CORS + 1))
    names = tuple(f"c{i}" for i in range(len(heights)))
    many = Geometry(cor_heights=heights, cor_names=names)  # a bare geometry may sample a line finely
    with pytest.raises(ParameterError, match=f"at most {params.MAX_CORS} centres of rotation") as info:
        Model(geometry=many, body=dataclasses.replace(Body(), mass_height=max(top, 0.2)))
    assert info.value.field == "geometry.cor_heights"
    # 6 muscles x 1000 fibres x 5 CoRs = 30,000 terms: the bound; one more pair of 1000 fibres exceeds it
    Model(muscles=_pairs(3, fibres=1000))
    with pytest.raises(ParameterError, match=r"at most 30,000 fibre-CoR terms .* got 40,000"):
        Model(muscles=_pairs(4, fibres=1000))


@pytest.mark.parametrize(("value", "shown"), [(-0.5, "-0.5"), (11.0, "11"), (float("nan"), "nan")])
def test_local_damping_outside_its_range_is_one_line_naming_the_field(capsys, value, shown):
    """local.damping, the factor on the local muscles' force-velocity damping: [0, 10] (MAX_LOCAL_DAMPING;
    docs/chain.md), refused by the dataclass and by the CLI in one line naming the field, exit 2; the
    edges 0 (stiffness only) and 10 are accepted, and config show prints the field with its unit."""
    from spinectl.cli import main
    from spinectl.model.params import MAX_LOCAL_DAMPING

    with pytest.raises(ParameterError, match="damping"):
        Local(damping=value)
    assert main(["stability", "--coupled", "--set", f"local.damping={value}"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "local.damping" in err and shown in err
    assert "Traceback" not in err
    Local(damping=0.0), Local(damping=MAX_LOCAL_DAMPING)
    assert main(["config", "show"]) == 0
    out = capsys.readouterr().out
    section = out[out.index("[local]") :]
    assert "# [1] Factor on the local muscles' damping" in section and "\ndamping = 1.0" in section


def test_side_names_name_every_muscle_and_are_validated():
    """geometry.side_names (the +x side first) names each pair's muscles: right and left in the coronal plane."""
    model = Model(geometry=Geometry(side_names=("right", "left")))
    assert model.muscle_names[:2] == (f"{model.pair_names[0]}_right", f"{model.pair_names[0]}_left")
    assert Model().muscle_names[:2] == (f"{model.pair_names[0]}_ventral", f"{model.pair_names[0]}_dorsal")
    with pytest.raises(ParameterError, match=r"side_names: must name 2 sides, the \+x side first \(got 1\)"):
        Geometry(side_names=("right",))
    with pytest.raises(ParameterError, match=r"side_names: must be unique \(repeated: 'left'\)"):
        Geometry(side_names=("left", "left"))
