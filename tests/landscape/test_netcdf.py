"""NetCDF files of landscapes carry checksums: a flipped bit is one line naming the file and what changed."""

from __future__ import annotations

import random
import warnings

import numpy as np
import pytest
import xarray as xr

from spinectl.cli import main
from spinectl.errors import ParameterError
from spinectl.landscape import netcdf, sweep
from spinectl.model.params import Model


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """A 3 x 3 sweep written by netcdf.save, its bytes, and the Dataset as written."""
    path = tmp_path_factory.mktemp("nc") / "n.nc"
    dataset = sweep.sweep(Model(), [0.0, 0.04, 0.08], [0.0, 0.04, 0.08], progress=False)
    netcdf.save(dataset, path)
    return path, path.read_bytes(), netcdf.load(path)


def _flipped(tmp_path, data: bytes, position: int, bit: int, name="flipped.nc"):
    damaged = bytearray(data)
    damaged[position] ^= 1 << bit
    path = tmp_path / name
    path.write_bytes(bytes(damaged))
    return path


def test_a_flipped_bit_in_a_value_is_one_line_naming_the_variable(written, tmp_path, capsys):
    """One bit of the stored float64 of the smallest minimum PCSA flipped (an exponent bit: the value
    changes by a factor, as 35.76 -> 43.76 cm^2 in a damaged file that plotted with exit 0 before):
    load raises naming the variable; plot exits 2 with that one line and draws nothing."""
    path, data, dataset = written
    value = np.nanmin(dataset["min_pcsa_cm2"].values)
    stored = np.float64(value).tobytes()
    assert data.count(stored) == 1  # the value's 8 bytes, uncompressed, once in the file
    damaged = _flipped(tmp_path, data, data.index(stored) + 6, 2)
    with pytest.raises(ParameterError, match="is damaged: variable 'min_pcsa_cm2' differs from what was written"):
        netcdf.load(damaged)
    assert main(["plot", str(damaged), "--out", str(tmp_path / "figs")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "min_pcsa_cm2" in err and not (tmp_path / "figs").exists()


def test_a_flipped_bit_in_config_toml_is_found(written, tmp_path):
    """The model is a global attribute: a flipped bit in its text (e.g. in the mass) is caught."""
    path, data, dataset = written
    at = data.index(b"mass = ")
    with pytest.raises(ParameterError, match="is damaged: its global attributes differ"):
        netcdf.load(_flipped(tmp_path, data, at + 7, 0))


def test_random_bit_flips_give_the_same_dataset_or_one_line(written, tmp_path):
    """60 single-bit flips at seeded random places: each file either loads as exactly the dataset written
    (a flip in unused bytes) or raises one ParameterError line (before: 2 in 3 loaded with other values,
    about 1 in 9 ended in a 'NetCDF: HDF error' traceback). Each file has its own name: netCDF-C caches
    open files by name."""
    path, data, dataset = written
    rng, outcomes = random.Random(26), {"same": 0, "refused": 0}
    for i in range(60):
        flipped = _flipped(tmp_path, data, rng.randrange(len(data)), rng.randrange(8), f"f{i}.nc")
        try:
            back = netcdf.load(flipped)
        except ParameterError as exc:
            assert "\n" not in str(exc) and repr(str(flipped)) in str(exc)
            outcomes["refused"] += 1
        else:
            xr.testing.assert_identical(back, dataset)
            outcomes["same"] += 1
    assert outcomes["refused"] > 40


def test_a_file_without_checksums_loads_with_a_one_line_warning(written, tmp_path, capsys):
    """A file written without checksums (spinectl before they were recorded; here xarray directly) loads,
    with a ChecksumWarning saying so; plot prints it as one line and draws."""
    path, data, dataset = written
    old = tmp_path / "old.nc"
    dataset.to_netcdf(old, engine="netcdf4")
    with pytest.warns(netcdf.ChecksumWarning, match="carries no checksums"):
        back = netcdf.load(old)
    xr.testing.assert_identical(back, dataset)
    assert main(["plot", str(old), "--out", str(tmp_path / "figs")]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("spinectl: warning:") and "carries no checksums" in err


def test_a_loaded_and_edited_dataset_is_saved_with_fresh_checksums(written, tmp_path):
    """load returns no checksum attributes, and save computes them anew: an edited copy saves and loads."""
    path, data, dataset = written
    assert netcdf.CHECKSUM not in dataset.attrs and all(
        netcdf.CHECKSUM not in v.attrs for v in dataset.variables.values()
    )
    edited = dataset.assign(min_pcsa_cm2=dataset["min_pcsa_cm2"] * 2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        back = netcdf.load(netcdf.save(edited, tmp_path / "edited.nc"))
    xr.testing.assert_identical(back, edited)


def test_a_name_the_netcdf_library_cannot_encode_is_one_line_both_ways(tmp_path, monkeypatch):
    """Under the C locale without Python's UTF-8 mode the file system's encoding is ASCII, and netCDF4 encodes
    names strictly in it: ``Λdir/k0.nc`` (as ``reproduce --out Λdir`` writes) ended in a UnicodeEncodeError
    traceback. Saving is refused before anything is written, loading in one line naming the input."""
    import sys

    from spinectl.errors import OutputError

    folder = tmp_path / "Λdir"
    folder.mkdir()
    (folder / "k0.nc").write_bytes(b"")  # only its name matters to the check
    monkeypatch.setattr(sys, "getfilesystemencoding", lambda: "ascii")
    with pytest.raises(OutputError, match="NetCDF library takes only names in the file system's encoding"):
        netcdf.save(xr.Dataset(), folder / "new.nc")
    assert not (folder / "new.nc").exists()
    with pytest.raises(ParameterError, match="^results: cannot open"):
        netcdf.load(folder / "k0.nc")
