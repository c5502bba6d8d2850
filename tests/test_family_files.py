"""OrbitFamily.save / load never destroy foreign data and say why a file is not a family
(issue 12 #4 and "OrbitFamily.load on garbage, truncated, empty or foreign files")."""

import os

import librate
import numpy as np
import pytest


@pytest.fixture(scope="module")
def fam(em):
    return librate.dro_family(em, x0=[0.9, 0.85, 0.8])


def _same(a, b):
    for k in ("state0", "state_half", "period", "jacobi", "eigenvalues", "stability_indices"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))


@pytest.mark.parametrize("suffix", [".nc", ".zarr"])
def test_round_trip_and_replace_own_file(tmp_path, fam, suffix):
    p = tmp_path / f"fam{suffix}"
    fam.save(p)
    _same(librate.OrbitFamily.load(p), fam)
    fam.save(p)  # a librate family file is replaced
    _same(librate.OrbitFamily.load(p), fam)
    assert sorted(x.name for x in tmp_path.iterdir()) == [p.name]  # no temporary left


def test_save_refuses_a_foreign_nc_file(tmp_path, fam):
    """Before: save() overwrote a foreign .nc file."""
    p = tmp_path / "data.nc"
    p.write_bytes(b"my precious data")
    with pytest.raises(FileExistsError, match="not a valid librate family file.*refusing to overwrite"):
        fam.save(p)
    assert p.read_bytes() == b"my precious data"


def test_save_refuses_a_foreign_netcdf_dataset(tmp_path, fam):
    import xarray as xr

    p = tmp_path / "other.nc"
    xr.Dataset({"t": ("x", np.arange(3.0))}).to_netcdf(p, engine="scipy")
    before = p.read_bytes()
    with pytest.raises(FileExistsError, match="missing state0"):
        fam.save(p)
    assert p.read_bytes() == before


def test_save_keeps_the_other_files_of_a_zarr_folder(tmp_path, fam):
    """Before: save() to a .zarr folder (mode "w") deleted every other file in it."""
    p = tmp_path / "fam.zarr"
    p.mkdir()
    (p / "notes.txt").write_text("mine")
    with pytest.raises(FileExistsError, match="refusing to overwrite"):
        fam.save(p)
    assert (p / "notes.txt").read_text() == "mine"


def test_save_into_an_empty_folder(tmp_path, fam):
    p = tmp_path / "fam.zarr"
    p.mkdir()
    fam.save(p)
    _same(librate.OrbitFamily.load(p), fam)


@pytest.mark.parametrize("content,why", [
    (b"", "empty"),
    (b"\x00garbage\xff" * 50, "cannot be read as netCDF"),
    (b"CDF\x01" + b"\x00" * 3, "cannot be read as netCDF"),
])
def test_load_garbage_nc_says_why(tmp_path, content, why):
    """Before: "cannot reshape", KeyError 'mu' or "not a valid NetCDF 3"."""
    p = tmp_path / "x.nc"
    p.write_bytes(content)
    with pytest.raises(ValueError, match=f"is not a librate family file.*{why}"):
        librate.OrbitFamily.load(p)


def test_load_truncated_nc(tmp_path, fam):
    p = tmp_path / "fam.nc"
    fam.save(p)
    data = p.read_bytes()
    p.write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError, match="not a librate family file|damaged librate family file"):
        librate.OrbitFamily.load(p)


def test_load_foreign_dataset_names_what_is_missing(tmp_path):
    import xarray as xr

    p = tmp_path / "x.nc"
    xr.Dataset({"t": ("x", np.arange(3.0))}, attrs={"kind": "dro"}).to_netcdf(p, engine="scipy")
    with pytest.raises(ValueError, match="not a librate family file: missing state0.*attribute mu"):
        librate.OrbitFamily.load(p)


def test_load_a_map_result_says_so(tmp_path):
    import xarray as xr

    p = tmp_path / "m.nc"
    xr.Dataset({"dwz": ("x", np.arange(3.0))}, attrs={"librate_result": "map"}).to_netcdf(p, engine="scipy")
    with pytest.raises(ValueError, match="it is a librate map result"):
        librate.OrbitFamily.load(p)


@pytest.mark.parametrize("var", ["period", "state0", "jacobi"])
def test_load_zarr_missing_a_chunk(tmp_path, fam, var):
    """Before: a .zarr family missing a chunk loaded with NaN periods."""
    p = tmp_path / "fam.zarr"
    fam.save(p)
    chunk = next(x for x in sorted((p / var).iterdir()) if not x.name.startswith("."))
    os.remove(chunk)
    with pytest.raises(ValueError, match=f"damaged librate family file: chunk\\(s\\) {var}/"):
        librate.OrbitFamily.load(p)


def test_load_zarr_with_an_altered_chunk(tmp_path, fam):
    import zarr

    p = tmp_path / "fam.zarr"
    fam.save(p)
    g = zarr.open_group(str(p), mode="r+", use_consolidated=False)
    per = g["period"][:]
    per[1] += 1e-9
    g["period"][:] = per
    with pytest.raises(ValueError, match="period do\\(es\\) not match the stored checksum"):
        librate.OrbitFamily.load(p)


def test_load_garbage_zarr_chunk(tmp_path, fam):
    p = tmp_path / "fam.zarr"
    fam.save(p)
    chunk = next(x for x in sorted((p / "period").iterdir()) if not x.name.startswith("."))
    chunk.write_bytes(os.urandom(chunk.stat().st_size))
    with pytest.raises(ValueError, match="damaged librate family file|not a librate family file"):
        librate.OrbitFamily.load(p)


def test_load_foreign_folder_and_wrong_suffix(tmp_path):
    d = tmp_path / "x.zarr"
    d.mkdir()
    (d / "a.txt").write_text("x")
    with pytest.raises(ValueError, match="is not a librate family file: it cannot be read as Zarr"):
        librate.OrbitFamily.load(d)
    f = tmp_path / "x.txt"
    f.write_text("x")
    with pytest.raises(ValueError, match="must end in .nc"):
        librate.OrbitFamily.load(f)
    with pytest.raises(FileNotFoundError):
        librate.OrbitFamily.load(tmp_path / "none.nc")


def test_verify_names_a_damaged_saved_result(tmp_path, fam):
    """`librate verify` / verify_result on results other than map stores: every variable is read
    and compared with the digests written by save_dataset (a deleted chunk read as NaN before)."""
    from click.testing import CliRunner
    from librate.app.cli import main
    from librate.app.results import save_family, verify_result

    p = save_family(fam, tmp_path / "family.zarr", attrs={"study": "{}"})
    assert verify_result(p)[0]
    r = CliRunner().invoke(main, ["verify", str(p)])
    assert r.exit_code == 0 and "ok" in r.output, r.output
    chunk = next(x for x in sorted((p / "period").iterdir()) if not x.name.startswith("."))
    chunk.unlink()
    ok, report = verify_result(p)
    assert not ok and "period/" in report and "missing" in report, report
    r = CliRunner().invoke(main, ["verify", str(p)])
    assert r.exit_code == 1 and "period/" in r.output, r.output
    with pytest.raises(ValueError, match="period"):
        librate.open_result(p, verify=True)
