"""An interrupted sweep leaves the previous output intact: outputs are written atomically (docs/robustness.md)."""

from __future__ import annotations

import pytest

from spinectl.cli import main
from spinectl.optimise import active_set


def test_interrupted_sweep_keeps_the_previous_file(tmp_path, monkeypatch, capsys):
    out = tmp_path / "landscape.nc"
    assert main(["sweep", "--E", "0:0.08:3", "--Lambda", "0:0.08:3", "--out", str(out)]) == 0
    before = out.read_bytes()

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt  # Ctrl-C in the middle of the solves

    monkeypatch.setattr(active_set, "solve_block", interrupted)
    code = main(["sweep", "--E", "0:0.08:5", "--Lambda", "0:0.08:5", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 130 and err.strip() == "spinectl: interrupted"
    assert out.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["landscape.nc"]  # no temporary left behind


@pytest.mark.parametrize(
    "command", [["plot", "missing.nc", "--out", "figs"], ["plot", "landscape.nc", "--out", "figs"]]
)
def test_plot_of_a_bad_dataset_is_one_line(tmp_path, monkeypatch, capsys, command):
    """A missing file, or a NetCDF file that is not a sweep, gives one line and exit 2."""
    import xarray as xr

    monkeypatch.chdir(tmp_path)
    xr.Dataset({"x": ("t", [1.0, 2.0])}).to_netcdf(tmp_path / "landscape.nc")
    assert main(command) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "results:" in err
    assert not (tmp_path / "figs").exists()


# --- valid or foreign inputs that crashed the readers (docs/robustness.md) ---------------------------


@pytest.fixture(scope="module")
def landscape(tmp_path_factory):
    """A 3 x 3 sweep, as `spinectl sweep` writes it, for the readers to be fed edited copies: without its
    checksums, as another program writes it (with them, every edit is refused as damage, netcdf.CHECKSUM)."""
    import xarray as xr

    from spinectl.landscape import netcdf

    path = tmp_path_factory.mktemp("sweep") / "good.nc"
    assert main(["sweep", "--E", "0:0.08:3", "--Lambda", "0:0.08:3", "--K", "0,15", "--out", str(path)]) == 0
    dataset = xr.load_dataset(path)
    for attrs in (dataset.attrs, *(variable.attrs for variable in dataset.variables.values())):
        attrs.pop(netcdf.CHECKSUM)
    return dataset


def _edited(landscape, how):
    """The landscape after one foreign edit: what a user, another tool or a damaged file could hand the readers."""
    ds = landscape.copy(deep=True)
    if how == "config_not_toml":
        ds.attrs["config_toml"] = "[body\nmass = 40"
    elif how == "config_not_a_model":
        ds.attrs["config_toml"] = ds.attrs["config_toml"].replace("[body]", "[body]\nmas = 3.0", 1)
    elif how == "repeated_K":
        ds = ds.assign_coords(K=[15.0, 15.0])
    elif how == "nan_coordinate":
        ds = ds.assign_coords(E=[0.0, float("nan"), 0.08])
    elif how == "other_dimensions":
        ds = ds.assign(min_pcsa_cm2=ds["min_pcsa_cm2"].isel(Lambda=0, drop=True))
    elif how == "extra_dimension":
        ds = ds.assign(status=ds["status"].expand_dims(run=2))
    elif how == "muscle_pcsa_dimension_lost":
        ds = ds.assign(pcsa_cm2=ds["pcsa_cm2"].isel(Lambda=0, drop=True))
    elif how in VALUES:  # one value of a solved point replaced: figures drew it silently
        name, value = VALUES[how]
        ds[name].values.flat[4] = value
    return ds


VALUES = {
    "infinite_pcsa": ("min_pcsa_cm2", float("inf")),
    "negative_pcsa": ("min_pcsa_cm2", -3.0),
    "negative_muscle_pcsa": ("pcsa_cm2", -1.0),
    "minus_infinite_torque": ("counter_torque_norm_Nm", float("-inf")),
    "nan_where_optimal": ("min_pcsa_cm2", float("nan")),
}


FOREIGN = {
    "config_not_toml": "config_toml: is not valid TOML",
    "config_not_a_model": "config_toml: is not a valid model (body.mas: unknown key 'mas'",
    "repeated_K": "coordinate K must not repeat a value",
    "nan_coordinate": "coordinate E must be finite",
    "other_dimensions": "min_pcsa_cm2 has dimensions ('K', 'E'), expected ('K', 'E', 'Lambda')",
    "extra_dimension": "status has dimensions ('run', 'K', 'E', 'Lambda')",
    "infinite_pcsa": "min_pcsa_cm2 must be finite and >= 0 (got inf at 1 value(s))",
    "negative_pcsa": "min_pcsa_cm2 must be finite and >= 0 (got -3 at 1 value(s))",
    "negative_muscle_pcsa": "pcsa_cm2 must be finite and >= 0 (got -1 at 1 value(s))",
    "minus_infinite_torque": "counter_torque_norm_Nm must be finite and >= 0 (got -inf",
    "nan_where_optimal": "min_pcsa_cm2 must be finite where the status is optimal (got nan",
    "muscle_pcsa_dimension_lost": "pcsa_cm2 has dimensions ('K', 'E', 'muscle')",
}


@pytest.mark.parametrize("how", FOREIGN)
def test_a_foreign_netcdf_file_is_one_line_for_load_and_plot(tmp_path, capsys, landscape, how):
    """Before: tomllib, xarray or matplotlib tracebacks from plot, netcdf.load and model_of."""
    from spinectl.errors import ParameterError
    from spinectl.landscape import netcdf

    path = tmp_path / "edited.nc"
    _edited(landscape, how).to_netcdf(path)
    with pytest.raises(ParameterError, match="results: .*" + FOREIGN[how].replace("(", r"\(").replace(")", r"\)")):
        netcdf.load(path)
    assert main(["plot", str(path), "--out", str(tmp_path / "figs")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "results:" in err and not (tmp_path / "figs").exists()


def test_model_of_an_edited_dataset_names_config_toml(landscape):
    """model_of, used on datasets in memory too, says which attribute is wrong."""
    from spinectl.errors import ParameterError
    from spinectl.landscape import netcdf

    for how in ("config_not_toml", "config_not_a_model"):
        with pytest.raises(ParameterError) as info:
            netcdf.model_of(_edited(landscape, how))
        assert info.value.field == "config_toml"


def test_plot_of_a_one_point_sweep_is_one_line(tmp_path, capsys):
    """A single point is a valid sweep (its numbers are the answer) but has no area to contour."""
    path = tmp_path / "one.nc"
    assert main(["sweep", "--E", "0:0:1", "--Lambda", "0:0:1", "--out", str(path)]) == 0
    assert main(["plot", str(path), "--out", str(tmp_path / "figs")]) == 2
    err = capsys.readouterr().err
    assert "grid: a landscape figure needs at least 2 values of E and 2 of Lambda (got 1 x 1)" in err
    assert err.count("\n") == 1 and not (tmp_path / "figs").exists()


@pytest.mark.parametrize(
    ("axes", "needle"),
    [
        (["--K", "15,15"], "K: must not repeat a value (repeated: 15)"),
        (["--E", "0:0:3"], "--E: with START = STOP must have NUM = 1"),
    ],
)
def test_a_repeated_coordinate_is_refused_before_the_sweep(tmp_path, monkeypatch, capsys, axes, needle):
    """Before: `--K 15,15` wrote a file with K = [15, 15] that plot could not read."""
    monkeypatch.setattr(active_set, "solve_block", lambda *a, **k: pytest.fail("solved before checking"))
    argv = ["sweep", "--E", "0:0.08:3", "--Lambda", "0:0.08:3", *axes, "--out", str(tmp_path / "x.nc")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1 and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "command",
    [
        ["sweep", "--E", "0:0.08:3", "--Lambda", "0:0.08:3", "--out", "a\nb.nc"],
        ["calibrate", "--out", "a\nb.toml", "--grid", "3", "--verify-grid", "3"],
        ["reproduce", "--points", "3", "--out", "a\nb"],
        ["plot", "good.nc", "--out", "fig\nures"],
    ],
)
def test_an_output_name_with_a_line_break_is_refused_before_the_work(tmp_path, monkeypatch, capsys, command):
    """Before: exit 0, a two-line listing, and a preset whose header comment broke its TOML."""
    monkeypatch.chdir(tmp_path)
    assert main(["sweep", "--E", "0:0.08:3", "--Lambda", "0:0.08:3", "--out", "good.nc"]) == 0
    capsys.readouterr()
    monkeypatch.setattr(active_set, "solve_block", lambda *a, **k: pytest.fail("solved before checking"))
    assert main(command) == 2
    err = capsys.readouterr().err
    assert "the name must be printable" in err and err.count("\n") == 1
    assert [p.name for p in tmp_path.iterdir()] == ["good.nc"]


def test_a_full_disk_in_the_netcdf_library_names_the_full_disk(tmp_path, monkeypatch):
    """netCDF-C reports a full disk in HDF5's words ('NetCDF: Can't open HDF5 attribute', seen on a 2 MB
    tmpfs): the message adds what the file system says, that no space is left (before: HDF5's words only)."""
    import os
    import types

    import xarray as xr

    from spinectl.errors import OutputError
    from spinectl.landscape import netcdf

    def failing(*args, **kwargs):
        raise RuntimeError("NetCDF: Can't open HDF5 attribute")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", failing)
    full = types.SimpleNamespace(f_bavail=3, f_frsize=4096)
    monkeypatch.setattr(os, "statvfs", lambda path: full)
    with pytest.raises(OutputError, match="Can't open HDF5 attribute; No space left on device"):
        netcdf.save(xr.Dataset({"a": ("x", [1.0])}), tmp_path / "x.nc")
    monkeypatch.setattr(os, "statvfs", lambda path: types.SimpleNamespace(f_bavail=10**6, f_frsize=4096))
    with pytest.raises(OutputError, match="HDF5 attribute$"):
        netcdf.save(xr.Dataset({"a": ("x", [1.0])}), tmp_path / "x.nc")
    assert list(tmp_path.iterdir()) == []
