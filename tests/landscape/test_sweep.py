"""Sweeps: grid orientation, chunking, the per-point method, NetCDF round trip and the CLI."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from spinectl import optimise
from spinectl.cli import main
from spinectl.errors import OutputError, ParameterError
from spinectl.landscape import netcdf, schema, sweep
from spinectl.model import chain, config, source
from spinectl.model.mechanics import segment_coefficients
from spinectl.model.params import Body, Model, MusclePair, Optimisation
from spinectl.model.stability import segment_stability
from spinectl.optimise.coupled import joint_optimum, least_local_stiffness

E_AXIS = np.array([0.0, 0.04, 0.08])
L_AXIS = np.array([0.0, 0.03, 0.05, 0.08])  # a different length, so that a transposed grid would fail


@pytest.fixture(scope="module")
def landscape():
    return sweep.sweep(Model(), E_AXIS, L_AXIS, progress=False, coupled=True)


def test_schema_units_and_orientation(landscape, model):
    assert landscape["min_pcsa_cm2"].dims == ("E", "Lambda")
    assert landscape["pcsa_cm2"].dims == ("E", "Lambda", "muscle")
    assert landscape["counter_torque_Nm"].dims == ("E", "Lambda", "segment")
    assert landscape["stiffness_per_cm2"].dims == ("E", "Lambda", "segment", "muscle")
    assert landscape["E"].attrs["units"] == "m" and landscape["Lambda"].attrs["units"] == "m"
    for name in schema.VARIABLES:
        assert name in landscape and "units" in landscape[name].attrs
    opt = optimise.solve_point(model, 0.04, 0.03)  # the reference at one grid point, by name
    here = landscape.sel(E=0.04, Lambda=0.03)
    assert float(here["min_pcsa_cm2"]) == pytest.approx(opt.min_pcsa * 1e4, rel=1e-6)
    np.testing.assert_allclose(here["counter_torque_Nm"], opt.counter_torque, rtol=1e-6, atol=1e-6)
    assert float(here["counter_torque_norm_Nm"]) == pytest.approx(opt.counter_torque_norm, rel=1e-6)


def test_coefficients_are_those_of_the_mechanics(landscape, model):
    coeffs = segment_coefficients(model, 0.08, 0.05)
    here = landscape.sel(E=0.08, Lambda=0.05)
    np.testing.assert_allclose(here["stiffness_per_cm2"], coeffs.stiffness_per_pcsa * 1e-4)
    np.testing.assert_allclose(here["inertia_kgm2"], coeffs.inertia)


def test_chunks_and_methods_give_the_same_dataset(landscape, model):
    chunked = sweep.sweep(model, E_AXIS, L_AXIS, chunk_size=5, progress=False, coupled=True)
    local = [  # the chain's SDPs: to the solver's tolerance, not polished
        "status",
        "local_stiffness_Nm_per_rad",
        "local_stiffness_total_Nm_per_rad",
        "joint_global_pcsa_cm2",
        "joint_local_pcsa_cm2",
    ]
    xr.testing.assert_allclose(chunked.drop_vars(local), landscape.drop_vars(local), rtol=1e-12)
    reference = sweep.sweep(model, E_AXIS, L_AXIS, method="per-point", progress=False, coupled=True)
    assert reference.attrs["points_solved_per_point"] == E_AXIS.size * L_AXIS.size
    for name in ("min_pcsa_cm2", "pcsa_cm2", "counter_torque_Nm"):
        np.testing.assert_allclose(reference[name], landscape[name], rtol=1e-6, atol=1e-6)
    # the least local stiffness: the stacked SDP of each chunk against one cvxpy SDP per point; the
    # optimum (the total) is unique, the minimiser need not be
    for other in (chunked, reference):
        total = other["local_stiffness_total_Nm_per_rad"]
        np.testing.assert_allclose(total, landscape["local_stiffness_total_Nm_per_rad"], rtol=1e-6)
        # the joint optimum: its objective (global + local, local.cost_weight = 1) is unique, its split
        # between the two nearly flat (1e-5 relative between solvers)
        cost = other["joint_global_pcsa_cm2"] + other["joint_local_pcsa_cm2"]
        expected = landscape["joint_global_pcsa_cm2"] + landscape["joint_local_pcsa_cm2"]
        np.testing.assert_allclose(cost, expected, rtol=1e-6)
        np.testing.assert_allclose(other["joint_local_pcsa_cm2"], landscape["joint_local_pcsa_cm2"], rtol=1e-4)


def test_netcdf_round_trip(landscape, model, tmp_path):
    path = netcdf.save(landscape, tmp_path / "r.nc")
    back = netcdf.load(path)
    xr.testing.assert_identical(back, landscape)
    assert netcdf.model_of(back) == model


def test_stiffness_lowers_the_minimum(model):
    """-K adds to dM/dalpha, so the stable set only grows: the minimum PCSA can only fall."""
    both = sweep.stiffness_sweep(model, [0.0, 15.0], E_AXIS, L_AXIS, progress=False)
    assert both["min_pcsa_cm2"].dims == ("K", "E", "Lambda")
    assert (both["min_pcsa_cm2"].sel(K=15.0) < both["min_pcsa_cm2"].sel(K=0.0)).all()


@pytest.mark.parametrize(
    ("spec", "expected"), [("0:0.08:81", np.linspace(0, 0.08, 81)), ("0.03", [0.03]), ("0:0:1", [0.0])]
)
def test_parse_grid(spec, expected):
    np.testing.assert_allclose(sweep.parse_grid(spec, "--E"), expected)


@pytest.mark.parametrize("spec", ["0:0.08", "a:b:c", "0.08:0:5", "0:1:0", "0:nan:3", "0:0.08:1000000000"])
def test_parse_grid_rejects(spec):
    with pytest.raises(ParameterError) as info:
        sweep.parse_grid(spec, "--E")
    assert info.value.field == "--E"


def test_cli_sweep_writes_netcdf(tmp_path, capsys):
    out = tmp_path / "r.nc"
    code = main(["sweep", "--E", "0:0.08:3", "--Lambda", "0:0.08:2", "--K", "0,15", "--out", str(out)])
    assert code == 0 and "12 points (12 solved" in capsys.readouterr().out
    ds = netcdf.load(out)
    assert ds.sizes["K"] == 2 and ds.sizes["E"] == 3 and ds.sizes["Lambda"] == 2


def test_cli_sweep_bad_input(tmp_path, capsys):
    code = main(["sweep", "--E", "0:0.5:3", "--out", str(tmp_path / "r.nc")])
    err = capsys.readouterr().err
    assert code == 2 and "E: must be in" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "r.nc").exists()


def test_load_rejects_what_is_not_a_sweep(tmp_path):
    other = tmp_path / "other.nc"
    xr.Dataset({"x": ("t", [1.0])}).to_netcdf(other)
    text = tmp_path / "text.nc"
    text.write_text("not netcdf")
    for path, needle in ((other, "not a spinectl sweep"), (text, "not a spinectl NetCDF file")):
        with pytest.raises(ParameterError) as info:
            netcdf.load(path)
        assert info.value.field == "results" and needle in str(info.value)


def test_an_absurd_grid_is_refused_before_any_work(model):
    axis = np.zeros(1001)
    with pytest.raises(ParameterError) as info:
        sweep.sweep(model, axis, axis)
    assert info.value.field == "grid"


def test_delay_margins_in_the_sweep_equal_the_margins_report():
    """Second path: the per-point ``margins.margins_report`` (per-point optimum, python-control
    alongside) gives the same gains, delay margins and verdicts as the vectorised sweep."""
    from spinectl.reflex import margins

    model = Model()
    E, L = np.array([0.0, 0.03]), np.array([0.04, 0.08])
    ds = sweep.sweep(model, E, L, progress=False)
    for e in E:
        for lam in L:
            report = margins.margins_report(model, float(e), float(lam))
            point = ds.sel(E=e, Lambda=lam)
            for k, seg in enumerate(report.segments):
                assert point.reflex_kp_Nm_per_rad.values[k] == pytest.approx(seg.kp, rel=1e-6)
                assert point.delay_margin_s.values[k] == pytest.approx(seg.delay_margin, rel=1e-6)
                assert bool(point.stable_at_delay.values[k]) == seg.stable_at_delay
            assert float(point.spine_delay_margin_s) == pytest.approx(min(s.delay_margin for s in report.segments))


def test_write_sweep_one_k_is_a_scalar_landscape(model, tmp_path):
    """One K: the plain sweep with that K (a scalar coordinate), written and returned."""
    out = tmp_path / "one.nc"
    dataset = sweep.write_sweep(model, [0.0, 0.08], [0.0], out, stiffnesses=[15.0], progress=False)
    assert "K" not in dataset.dims and float(dataset["K"]) == 15.0
    assert netcdf.load(out).identical(dataset)
    default = sweep.write_sweep(model, [0.0], [0.0], tmp_path / "default.nc", progress=False)
    assert float(default["K"]) == model.passive.stiffness


def test_write_sweep_checks_its_file_before_solving(model, tmp_path, monkeypatch):
    (tmp_path / "taken.nc").mkdir()
    monkeypatch.setattr(sweep, "sweep", lambda *a, **k: pytest.fail("the sweep ran"))
    with pytest.raises(OutputError, match="cannot write"):
        sweep.write_sweep(model, [0.0], [0.0], tmp_path / "taken.nc")
    with pytest.raises(ParameterError, match=r"--out: must end in \.nc"):  # NetCDF under another name
        sweep.write_sweep(model, [0.0], [0.0], tmp_path / "x.csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["taken.nc"]


def test_describe(landscape):
    """12 points, all feasible on the default model's grid; ranges as the data's own extremes."""
    pcsa, torque = landscape["min_pcsa_cm2"].values, landscape["counter_torque_norm_Nm"].values
    assert sweep.describe(landscape) == (
        f"{source.header(Model())}: 12 points (12 solved, 0 infeasible or failed); "
        f"min PCSA {pcsa.min():.1f}-{pcsa.max():.1f} cm2, "
        f"||CT|| {torque.min():.1f}-{torque.max():.1f} N m"
    )
    nothing = landscape.copy()
    nothing["min_pcsa_cm2"] = nothing["min_pcsa_cm2"] * np.nan
    assert sweep.describe(nothing).endswith(": 12 points (0 solved, 12 infeasible or failed)")


def test_an_absurd_stiffness_gets_the_true_minimum_with_status_optimal():
    """K = 1e12 N m/rad: the stiffness rows are slack, so the minimum PCSA is that of any K large
    enough to make them slack, e.g. K = 1e4 (solved well-scaled, status 'optimal' before the fix too),
    about 0.02 cm^2 (the damping rows alone). Before: 'optimal_inaccurate' or 'infeasible'
    (4e10 cm^2 was reported)."""
    from spinectl.model.config import set_parameter

    axes = ([0.0, 0.04], [0.0, 0.04])
    absurd = sweep.sweep(set_parameter(Model(), "passive.stiffness", 1e12), *axes)
    stiff = sweep.sweep(set_parameter(Model(), "passive.stiffness", 1e4), *axes)
    assert np.all(stiff["status"].values == "optimal") and np.all(absurd["status"].values == "optimal")
    np.testing.assert_allclose(absurd["min_pcsa_cm2"], stiff["min_pcsa_cm2"], rtol=1e-6)
    assert np.all(absurd["min_pcsa_cm2"].values < 0.05)


def test_describe_warns_of_inaccurate_points():
    """A number whose status is optimal_inaccurate is never printed without a warning."""
    ds = sweep.sweep(Model(), [0.0, 0.04], [0.0])
    assert "WARNING" not in sweep.describe(ds)
    ds["status"][0] = "optimal_inaccurate"
    assert "WARNING: 1 inaccurate (status optimal_inaccurate" in sweep.describe(ds)


def test_local_stiffness_is_the_chain_sdp_at_the_chosen_activation(landscape, model):
    """local_stiffness_Nm_per_rad: optimise.coupled.least_local_stiffness (cvxpy, per point) at the point's
    PCSA; at A it is 391 N m/rad in total (docs/chain.md, the table of the finding), and every k makes
    diag(k) - K >= mu I by numpy's eigvalsh."""
    here = landscape.sel(E=0.04, Lambda=0.03)
    pcsa = here["pcsa_cm2"].values * 1e-4
    expected = least_local_stiffness(model, 0.04, 0.03, pcsa).local_stiffness
    assert float(here["local_stiffness_total_Nm_per_rad"]) == pytest.approx(expected.sum(), rel=1e-6)
    assert landscape["local_stiffness_Nm_per_rad"].dims == ("E", "Lambda", "segment")
    stiffness = chain.chain_coefficients(model, 0.04, 0.03).stiffness(pcsa)
    margin = np.linalg.eigvalsh(np.diag(here["local_stiffness_Nm_per_rad"].values) - stiffness)[0]
    assert margin >= model.optimisation.stability_margin * (1 - 1e-9)
    at_a = float(landscape["local_stiffness_total_Nm_per_rad"].sel(E=0.0, Lambda=0.0))
    assert at_a == pytest.approx(391, abs=0.5)


def test_the_chains_sdps_only_on_request(landscape):
    """Without coupled=True a sweep has every variable but the SDPs of schema.ON_REQUEST, the same values."""
    plain = sweep.sweep(Model(), E_AXIS, L_AXIS, progress=False)
    assert set(plain.data_vars) == set(schema.VARIABLES) - set(schema.ON_REQUEST)
    xr.testing.assert_identical(plain, landscape.drop_vars(schema.ON_REQUEST))


def test_joint_optimum_is_the_chain_sdp(landscape, model):
    """joint_*_pcsa_cm2: optimise.coupled.joint_optimum (cvxpy, per point); at A 33.0 cm^2 global and
    13.2 cm^2 local (docs/chain.md, the finding), less in total than the paper's 63.7 cm^2 of global muscle."""
    here = landscape.sel(E=0.0, Lambda=0.0)
    expected = joint_optimum(model, 0.0, 0.0)
    cost = float(here["joint_global_pcsa_cm2"] + here["joint_local_pcsa_cm2"])
    assert cost == pytest.approx((expected.total_pcsa + expected.total_local_pcsa) * 1e4, rel=1e-6)
    assert float(here["joint_global_pcsa_cm2"]) == pytest.approx(33.0, abs=0.05)
    assert float(here["joint_local_pcsa_cm2"]) == pytest.approx(13.2, abs=0.05)
    assert cost < float(here["min_pcsa_cm2"])


def test_coupled_margin_is_that_of_the_chain_at_the_chosen_activation(landscape, model):
    """coupled_margin_Nm_per_rad: the smallest eigenvalue of -K of model.chain at the point's PCSA,
    by numpy's eigvalsh on the matrix assembled here; negative (unstable chain) everywhere on this grid."""
    here = landscape.sel(E=0.04, Lambda=0.03)
    stiffness = chain.chain_coefficients(model, 0.04, 0.03).stiffness(here["pcsa_cm2"].values * 1e-4)
    expected = np.linalg.eigvalsh(-stiffness)[0]
    assert float(here["coupled_margin_Nm_per_rad"]) == pytest.approx(expected, rel=1e-6)
    assert landscape["coupled_margin_Nm_per_rad"].dims == ("E", "Lambda")
    assert float(landscape["coupled_margin_Nm_per_rad"].max()) < 0


def test_the_sweep_reports_the_slowest_time_constant_of_every_optimum():
    """slowest_time_constant_s at a grid point is that of segment_stability at the point's chosen PCSA."""
    preset = config.load_preset("wagner2012")
    axis = np.array([0.0, 0.03])
    land = sweep.sweep(preset, axis, np.array([0.0, 0.04]), progress=False)
    here = land.sel(E=0.03, Lambda=0.04)
    pcsa = here["pcsa_cm2"].values * 1e-4
    expected = segment_stability(preset, 0.03, 0.04, pcsa).slowest_time_constant
    assert float(here["slowest_time_constant_s"]) == pytest.approx(expected, rel=1e-9)
    assert land["slowest_time_constant_s"].dims == ("E", "Lambda")


def _random_model(rng) -> Model:
    """A random valid model, as tests/suites/test_properties.py draws them: 1 to 3 pairs whose fibres start
    above y = 0.165 m and end below y = -0.015 m (clear of every CoR), mass 10-100 kg at 0.2-0.5 m."""
    pairs = tuple(
        MusclePair(
            f"pair{i}",
            (rng.uniform(0.02, 0.20), rng.uniform(0.165, 0.30)),
            (rng.uniform(0.02, 0.20), rng.uniform(-0.05, -0.015)),
            rng.uniform(0.0, 0.02),
            int(rng.integers(1, 6)),
        )
        for i in range(int(rng.integers(1, 4)))
    )
    body = Body(mass=rng.uniform(10.0, 100.0), mass_height=rng.uniform(0.2, 0.5), radius_of_gyration=0.1)
    activation = str(rng.choice(["paired", "independent"]))
    return Model(body=body, muscles=pairs, optimisation=Optimisation(activation=activation))


@pytest.mark.parametrize("case", ["paper", "random-1", "random-2", "coupled"])
def test_one_pass_over_several_k_gives_each_sweep_bit_for_bit(case):
    """passive_sweeps computes the coefficients once per chunk for models that differ in K alone: each of its
    landscapes is that of the model's own sweep, bit for bit (the second path: one full sweep per model), for
    K = 0, 15 and a random K in both conventions, with chunks that split the grid; on the paper's preset and
    grid (at 4 mm), on random geometries, and with the chain's SDPs."""
    rng = np.random.default_rng(len(case))
    e_axis, l_axis, chunk = E_AXIS, L_AXIS, 5
    if case == "paper":
        base, e_axis, chunk = config.load_preset("wagner2012"), np.linspace(0.0, 0.08, 21), 100
        l_axis = e_axis
    else:
        base = Model() if case == "coupled" else _random_model(rng)
    passive = [(0.0, "physical"), (15.0, "physical"), (15.0, "paper"), (rng.uniform(0.0, 30.0), "paper")]
    models = [config.set_parameters(base, {"passive.stiffness": k, "passive.convention": c}) for k, c in passive]
    if case == "coupled":
        models = models[:2]
    options = {"chunk_size": chunk, "progress": False, "coupled": case == "coupled"}
    together = sweep.passive_sweeps(models, e_axis, l_axis, **options)
    for model, landscape in zip(models, together, strict=True):
        alone = sweep.sweep(model, e_axis, l_axis, **options)
        xr.testing.assert_identical(landscape, alone)  # exact equality of every value, NaN where NaN


def test_one_pass_refuses_models_that_differ_in_more_than_k(model):
    other = config.set_parameters(model, {"passive.stiffness": 15.0, "body.mass": 41.0})
    for models in ([], [model, other]):
        with pytest.raises(ParameterError) as info:
            sweep.passive_sweeps(models, E_AXIS, L_AXIS, progress=False)
        assert info.value.field == "models"


def test_a_landscape_stacked_over_k_names_every_k_and_no_k_override():
    """A file over K = 0 and 15 (``sweep --K 0,15``, reproduce's landscapes.nc) said "K = 0 N m/rad ...;
    overridden: passive.stiffness", the first K's model: K is its coordinate, so the source line names
    every K and only what the user overrode."""
    model = config.apply_overrides(config.load_preset(config.DEFAULT_PRESET), ["body.mass=30"])
    both = sweep.stiffness_sweep(model, [0.0, 15.0], [0.0, 0.08], [0.0], progress=False)
    assert both.attrs["model"] == (
        f"preset {config.DEFAULT_PRESET}, K = 0, 15 N m/rad, convention {model.passive.convention}; "
        "overridden: body.mass"
    )
    assert both.attrs["overridden"] == "body.mass"


def test_sweep_and_stability_agree_on_an_optimum_beyond_any_muscle():
    """A 1000 kg body on fibres of 5e4 N/m^2 needs more than 1000 cm^2 per muscle: the sweep and
    `stability` (which refused its own optimum as a unit slip before) give the same number."""
    import dataclasses

    from spinectl.optimise.stabilising import stability_at

    base = config.load_preset("wagner2012")
    heavy = base.replace(
        body=dataclasses.replace(base.body, mass=1000.0),
        fibre=dataclasses.replace(base.fibre, specific_tension=5e4),
    )
    landscape = sweep.sweep(heavy, [0.03], [0.04], progress=False)
    point = stability_at(heavy, 0.03, 0.04)
    assert str(landscape["status"].values[0, 0]) == "optimal"
    assert landscape["pcsa_cm2"].values[0, 0].max() > 1000.0
    np.testing.assert_allclose(landscape["min_pcsa_cm2"].values[0, 0], point.min_pcsa * 1e4, rtol=1e-6)
