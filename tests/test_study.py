"""Studies (TOML, validated by pydantic before any work) and results on disk (open_result).

Reference for the error paths: the rules written on the schema's fields (``Field(description=...)`` in librate.app.study) and the module
docstring; every message must name the key (dotted), the value given and what is allowed.
Round trips are checked for exact equality of the saved numbers.
"""

import json
import math

import librate
import numpy as np
import pytest

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib
from helpers import edit
from librate.app.jobs import run_family, run_map, run_solve
from librate.app.results import read_attrs, save_dataset, save_family
from librate.app.study import EXAMPLE_STUDY, Study, StudyError, apply_overrides

TINY = {"orbits.x0": {"start": 0.9, "stop": 0.5, "num": 3}, "rates.wz0.num": 50}


@pytest.fixture
def base() -> dict:
    """The example study (what `librate init` writes), shrunk to a tiny grid."""
    return apply_overrides(tomllib.loads(EXAMPLE_STUDY), TINY)




# --- the example and the builders ----------------------------------------------------------------
def test_the_example_study_validates_for_every_command():
    data = tomllib.loads(EXAMPLE_STUDY)
    for purpose in (None, "family", "solve", "map"):
        st = Study.from_dict(data, purpose=purpose)
        assert st.orbits.kind == "dro" and st.body.kz == 0.8
    assert st.wz0_values().tolist() == np.linspace(-3.0, 2.0, 300).tolist()


def test_study_error_is_a_value_error_listing_every_problem():
    with pytest.raises(ValueError) as info:
        Study.from_dict({"body": {"kz": 2.0}, "solver": {"rtol": "tight"}, "extra": 1})
    err = info.value
    assert isinstance(err, StudyError)
    assert len(err.problems) == 3
    text = str(err)
    assert text.startswith("invalid study: 3 problems")
    for p in err.problems:
        assert f"\n  - {p}" in text


def test_builders(base):
    st = Study.from_dict(base, purpose="map")
    em = st.build_system()
    assert em == librate.System.preset("earth-moon")
    assert st.kz_values().tolist() == [0.8]
    assert st.build_body() == librate.RigidBody.from_kz(0.8)
    assert st.build_srp() is None and st.n_periods() == 1
    fam = st.build_orbits()
    assert isinstance(fam, librate.OrbitFamily) and fam.x0.tolist() == pytest.approx([0.9, 0.7, 0.5], abs=1e-15)
    # relative rates: wz0 = phidot0 + 1
    rel = Study.from_dict(edit(edit(base, "rates.wz0"), "rates.phidot0", [-1.0, 0.0, 0.5]))
    assert rel.wz0_values().tolist() == [0.0, 1.0, 1.5]


def test_inertia_custom_system_and_srp_geometry():
    st = Study.from_dict({
        "system": {"mu": 0.0121505856, "lu_km": 384400.0, "tu_s": 375190.25852, "radii_km": [6378.0, 1737.0], "name": "my-em"},
        "orbits": {"sun_resonance": [2]},
        "body": {"ix": 12.12e6, "iy": 89.68e6, "iz": 96.95e6, "mass_kg": 4.0e5},
        "torques": {"srp": {"area_m2": 100.0, "offset_m": 2.0, "cs": 0.4, "theta_sun0": 0.3}},
        "rates": {"wz0": {"start": -1.6, "stop": 1.2, "num": 50}},
    }, purpose="solve")
    sys_ = st.build_system()
    assert (sys_.mu, sys_.lu_km, sys_.r1_km, sys_.name) == (0.0121505856, 384400.0, 6378.0, "my-em")
    assert st.kz_values()[0] == pytest.approx((89.68e6 - 12.12e6) / 96.95e6, rel=1e-15)
    body = st.build_body()
    assert body.moments == (12.12e6, 89.68e6, 96.95e6) and body.mass_kg == 4.0e5
    plate = st.build_srp()
    # eps = P A d TU^2 / Iz (docs/physics.md, solar radiation pressure)
    assert plate.eps == pytest.approx(4.56e-6 * 100.0 * 2.0 * 375190.25852**2 / 96.95e6, rel=1e-12)
    assert (plate.cs, plate.cd, plate.sun.theta0) == (0.4, 0.0, 0.3)
    assert st.n_periods() == 2  # the 1:2 Sun-resonant orbit: one Sun period


def test_old_sun_phase_key_still_read_with_a_warning():
    """[torques.srp] theta0 was renamed theta_sun0: the old key still works, with a FutureWarning
    naming the new one; giving both is an error."""
    data = {"orbits": {"sun_resonance": [2]}, "body": {"kz": 0.6}, "torques": {"srp": {"eps": 0.02, "theta0": 0.3}},
            "rates": {"wz0": {"start": -1.6, "stop": 1.2, "num": 50}}}
    with pytest.warns(FutureWarning, match="theta_sun0"):
        st = Study.from_dict(data, purpose="solve")
    assert st.build_srp().sun.theta0 == 0.3 and data["torques"]["srp"] == {"eps": 0.02, "theta0": 0.3}
    data["torques"]["srp"]["theta_sun0"] = 0.3
    with pytest.raises(StudyError, match="give only theta_sun0"):
        Study.from_dict(data)


def test_json_round_trip_and_overrides(base):
    st = Study.from_dict(base)
    again = Study.from_json(st.to_json())
    assert again.to_dict() == st.to_dict()
    assert json.loads(st.to_json())["rates"]["wz0"] == {"start": -3.0, "stop": 2.0, "num": 50}
    ov = apply_overrides(base, {"body.kz": "[0.2, 0.5]", "rates.wz0": "{start = 0, stop = 1, num = 5}", "output.folder": "runs/a"})
    st2 = Study.from_dict(ov)
    assert st2.kz_values().tolist() == [0.2, 0.5] and st2.wz0_values().size == 5 and st2.output.folder == "runs/a"


def test_from_toml_paths_and_syntax_errors(tmp_path):
    good = tmp_path / "s.toml"
    good.write_text(EXAMPLE_STUDY)
    st = Study.from_toml(good, overrides={"rates.wz0.num": 20})
    assert st.output_dir() == tmp_path / "librate-out"  # relative to the study file
    assert st.output_dir("elsewhere").name == "elsewhere"
    bad = tmp_path / "bad.toml"
    bad.write_text("[body]\nkz = \n")
    with pytest.raises(StudyError, match=r"not valid TOML.*line 2"):
        Study.from_toml(bad)
    with pytest.raises(StudyError, match="not found"):
        Study.from_toml(tmp_path / "missing.toml")


# --- every error path -----------------------------------------------------------------------------
# (change to the valid tiny study, purpose, key named, value shown, what is allowed)
CASES = [
    # unknown keys
    ({"sytem": {"preset": "earth-moon"}}, None, "sytem", '{preset = "earth-moon"}', "allowed keys in the top level",
     "did you mean `system`"),
    ({"body.kzz": 0.8}, None, "body.kzz", "0.8", "allowed keys in [body]: kz, ix, iy, iz, mass_kg, flexible", "did you mean `body.kz`"),
    ({"orbits.x0.step": 0.1}, None, "orbits.x0.step", "0.1", "allowed keys in [orbits.x0]: start, stop, num", None),
    ({"torques.srp": {"eps": 0.01, "colour": "red"}}, None, "torques.srp.colour", '"red"', "allowed keys in [torques.srp]", None),
    # wrong types
    ({"body.kz": "0.8"}, None, "body.kz", '"0.8"', "a number in [-1, 1]", None),
    ({"solver.n_periods": 1.5}, None, "solver.n_periods", "1.5", "an integer in [1, 1000]", None),
    ({"orbits.x0": "0.9 to 0.5"}, None, "orbits.x0", '"0.9 to 0.5"', "a list of x0 values (LU) or a table {start, stop, num}", None),
    ({"orbits.x0": [0.9, "a"]}, None, "orbits.x0[1]", '"a"', "a list of x0 values", None),
    ({"rates.wz0.num": 50.0}, None, "rates.wz0.num", "50.0", "an integer", None),
    ({"output.figures": "map"}, None, "output.figures", '"map"', "a list of figure names", None),
    ({"torques.gravity_gradient": "earth"}, None, "torques.gravity_gradient", '"earth"', "a list of primaries", None),
    ({"body": 0.8}, None, "body", "0.8", "a table [body]", None),
    ({"title": 3}, None, "title", "3", "a string", None),
    # out of range
    ({"body.kz": 1.5}, None, "body.kz", "1.5", "a number in [-1, 1]", "less than or equal to 1"),
    ({"body.kz": [0.5, -1.2]}, None, "body.kz[1]", "-1.2", "a number in [-1, 1]", None),
    ({"body.kz": {"start": -2.0, "stop": 0.5, "num": 3}}, None, "body.kz.start", "-2.0", "a number in [-1, 1]", None),
    ({"solver.rtol": 1e-20}, None, "solver.rtol", "1e-20", "a number in [1e-15, 1e-3]", None),
    ({"solver.phi0": float("nan")}, None, "solver.phi0", "nan", "[-2 pi, 2 pi]", "finite"),
    ({"system.preset": "earth-mars"}, None, "system.preset", '"earth-mars"', "'earth-moon', 'earth-moon-jpl'", None),
    ({"system": {"mu": 0.7, "lu_km": 1.0, "tu_s": 1.0}}, None, "system.mu", "0.7", "(0, 0.5]", None),
    ({"orbits.kind": "nrho"}, None, "orbits.kind", '"nrho"', "'dro', 'lyapunov' or 'halo'", None),
    ({"orbits.x0": [0.9, 1.2]}, None, "orbits.x0", "[0.9, 1.2]", "(-mu, 1 - mu)", "-mu < x0 < 1 - mu"),
    ({"orbits.resonance": [0]}, None, "orbits.resonance[0]", "0", "integers k >= 1", None),
    ({"orbits.x0": {"start": 0.9, "stop": 0.5, "num": 0}}, None, "orbits.x0.num", "0", "an integer in [1, 1000000]", None),
    ({"orbits": {"period_days": [-3.0]}}, None, "orbits.period_days", "[-3.0]", "a list of periods (days)", "> 0 days"),
    ({"body": {"ix": -1.0, "iy": 2.0, "iz": 2.0}}, None, "body.ix", "-1.0", "a number > 0", None),
    ({"torques.srp": {"eps": 0.01, "cs": 1.5}}, None, "torques.srp.cs", "1.5", "a number in [0, 1]", None),
    ({"rates.wz0.num": 1}, "map", "rates.wz0.num", "1", "an integer in [2, 1000000]", "at least 2 values"),
    ({"rates.wz0": [1.0, 0.5, 2.0]}, None, "rates.wz0", "[1.0, 0.5, 2.0]", "strictly increasing", None),
    ({"rates.wz0.stop": -4.0}, None, "rates.wz0.stop", "-4.0", "a number > rates.wz0.start", "greater than rates.wz0.start = -3.0"),
    ({"output.format": "hdf5"}, None, "output.format", '"hdf5"', "'zarr' or 'netcdf'", None),
    ({"output.figures": ["map", "heat"]}, None, "output.figures[1]", '"heat"', "'family', 'period'", None),
    # inconsistent combinations
    ({"system.mu": 0.01}, None, "system.mu", "0.01", "either system.preset alone", "cannot be combined with system.preset"),
    ({"system": {"mu": 0.01, "lu_km": 1000.0}}, None, "system.tu_s", None, "a number > 0, the time unit",
     "needs system.mu, system.lu_km and system.tu_s"),
    ({"orbits.point": 2}, None, "orbits.point", "2", "for 'lyapunov' and 'halo'", 'does not apply to orbits.kind = "dro"'),
    ({"orbits.kind": "lyapunov", "orbits.x0": [0.8], "orbits.branch": "north"}, None, "orbits.branch", '"north"',
     "only with orbits.kind = 'halo'", None),
    ({"orbits": {"z0": [0.1]}}, None, "orbits.z0", "[0.1]", "only with orbits.kind = 'halo'", None),
    ({"orbits.members": 5}, None, "orbits.members", "5", "at most one of orbits.x0", "cannot be combined with orbits.x0"),
    ({"body.ix": 1.0}, None, "body.ix", "1.0", "either body.kz, or body.ix, body.iy and body.iz", None),
    ({"body": {"ix": 1.0, "iy": 1.0}}, None, "body.iz", None, "a number > 0", "needs all three"),
    ({"body": {"ix": 1.0, "iy": 1.0, "iz": 3.0}}, None, "body.iz", "3.0", "each <= the sum of the other two", "triangle inequality"),
    ({"body": {}}, None, "body.kz", None, "a number in [-1, 1]", "give body.kz, or body.ix"),
    ({"torques.srp": {"eps": 0.01, "area_m2": 10.0}}, None, "torques.srp.area_m2", "10.0", "either torques.srp.eps, or", None),
    ({"torques.srp": {"offset_m": 1.0}}, None, "torques.srp.area_m2", None, "a number > 0, the plate's area", "missing"),
    ({"torques.srp": {"eps": 0.01, "cs": 0.7, "cd": 0.5}}, None, "torques.srp.cd", "0.5", "(cs + cd <= 1)", "exceeds 1"),
    ({"torques.srp": {"area_m2": 10.0, "offset_m": 1.0}}, None, "torques.srp.area_m2", "10.0",
     "the geometry with body.ix/iy/iz", "needs the body's Iz"),
    ({"rates.phidot0": [0.0, 1.0]}, None, "rates.phidot0", "[0.0, 1.0]", "either rates.wz0 or rates.phidot0", None),
    ({"rates": {}}, None, "rates.wz0", None, "inertial initial rates", "missing"),
    # what a command needs
    ({"body": ...}, "map", "body", None, None, "missing section [body]"),
    ({"rates": ...}, "solve", "rates", None, None, "missing section [rates]"),
    ({"orbits": {"kind": "halo"}}, "map", "orbits.kind", '"halo"', "'dro' or 'lyapunov'", "planar"),
    ({"torques.gravity_gradient": ["earth"]}, "map", "torques.gravity_gradient", '["earth"]', '["earth", "moon"]', "both primaries"),
    ({"torques.srp": {"eps": 0.01}}, "solve", "orbits.sun_resonance", None, "a list of integers k >= 1", "Sun-resonant"),
    ({"torques.srp": {"eps": 0.01}, "orbits": {"sun_resonance": [2]}, "solver.n_periods": 3}, "map", "solver.n_periods", "3",
     "a multiple of 2", None),
]


@pytest.mark.parametrize("change, purpose, key, value, allowed, extra", CASES, ids=[c[2] + ":" + str(i) for i, c in enumerate(CASES)])
def test_each_config_error_names_the_key_the_value_and_what_is_allowed(base, change, purpose, key, value, allowed, extra):
    data = base
    for k, v in change.items():
        data = edit(data, k, v)
    with pytest.raises(StudyError) as info:
        Study.from_dict(data, purpose=purpose)
    problems = info.value.problems
    assert len(problems) == 1, problems  # one clear message per problem
    msg = problems[0]
    if value is None:
        assert msg.startswith(f"{key}: "), msg
    else:
        assert msg.startswith(f"{key} = {value}: "), msg
    if allowed is not None:
        assert allowed in msg.split("; allowed: ", 1)[-1] or allowed in msg, msg
        assert "allowed" in msg, msg
    if extra is not None:
        assert extra in msg, msg


def test_the_same_study_is_valid_for_a_family_but_not_for_a_map(base):
    halo = edit(edit(base, "orbits", {"kind": "halo", "point": 1, "branch": "north"}), "body")
    Study.from_dict(halo, purpose="family")
    with pytest.raises(StudyError) as info:
        Study.from_dict(halo, purpose="map")
    assert [p.split(":")[0] for p in info.value.problems] == ["body", 'orbits.kind = "halo"']


def test_a_valid_study_can_be_checked_again_for_a_command(base):
    st = Study.from_dict(edit(base, "rates"))
    assert st.check("family") is not None
    with pytest.raises(StudyError, match="missing section \\[rates\\]"):
        st.check("map")
    with pytest.raises(ValueError, match="purpose"):
        Study.from_dict(base, purpose="plot")


# --- results --------------------------------------------------------------------------------------
@pytest.mark.parametrize("fmt", ["zarr", "netcdf"])
def test_family_round_trip(tmp_path, base, fmt):
    st = Study.from_dict(edit(base, "output.format", fmt))
    fam, path = run_family(st, tmp_path)
    assert path.name == ("family.zarr" if fmt == "zarr" else "family.nc")
    back = librate.open_result(path)
    assert isinstance(back, librate.OrbitFamily)
    for a in ("state0", "state_half", "period", "jacobi", "eigenvalues", "stability_indices"):
        assert np.array_equal(getattr(back, a), getattr(fam, a)), a
    assert back.kind == "dro" and back.system == fam.system
    attrs = read_attrs(path)
    assert attrs["librate_result"] == "family" and attrs["librate_version"] == librate.__version__
    assert Study.from_json(attrs["study"]).to_dict() == st.to_dict()
    # an output folder holding one result opens too
    assert isinstance(librate.open_result(tmp_path), librate.OrbitFamily)


def test_selected_members_are_saved_as_a_family(tmp_path):
    st = Study.from_dict({"orbits": {"kind": "dro", "resonance": [2, 3]}})
    fam, path = run_family(st, tmp_path)
    assert len(fam) == 2
    assert fam.period.tolist() == pytest.approx([math.pi, 2 * math.pi / 3], abs=1e-10)
    assert np.array_equal(librate.open_result(path).period, fam.period)


def test_map_and_solutions_round_trip(tmp_path, base, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "librate.app.runner", None)  # the periodicity_map fallback
    st = Study.from_dict(base, purpose="map")
    ds, path = run_map(st, tmp_path / "m")
    assert path == tmp_path / "m" / "map.zarr"
    back = librate.open_result(path)
    for v in ("dwz", "dphi", "phi_T", "sol_wz0", "sol_n"):
        assert np.array_equal(back[v].values, ds[v].values, equal_nan=True), v
    assert list(back["sol_kind"].values) == list(ds["sol_kind"].values)
    assert back.attrs["librate_result"] == "map" and back.attrs["librate_version"] == librate.__version__
    assert json.loads(back.attrs["study"]) == st.to_dict()
    assert back["dwz"].attrs["units"] == "1/TU" and back["wz0"].attrs["units"] == "1/TU"
    # the same rows as periodicity_map itself
    ref = librate.periodicity_map(st.build_orbits(), kz=0.8, wz0=st.wz0_values())
    assert np.array_equal(ref["dwz"].values, back["dwz"].values, equal_nan=True)

    sols, spath = run_solve(Study.from_dict(edit(base, "output.format", "netcdf"), purpose="solve"), tmp_path / "s")
    assert spath.suffix == ".nc"
    sback = librate.open_result(spath)
    assert sback.attrs["librate_result"] == "solutions"
    for v in ("sol_wz0", "sol_phi0", "sol_n", "sol_x0", "sol_residual"):
        assert np.array_equal(sback[v].values, sols[v].values), v
    assert list(sback["sol_kind"].values.astype(str)) == list(sols["sol_kind"].values)
    # the table is what find_periodic_attitudes finds orbit by orbit
    fam = st.build_orbits()
    direct = librate.find_periodic_attitudes(fam[1], kz=0.8, wz0_range=(-3.0, 2.0), n_grid=50)
    mine = sols["sol_wz0"].values[sols["sol_orbit"].values == 1]
    assert mine.tolist() == [s.wz0 for s in direct]


def test_results_refuse_foreign_paths_and_non_results(tmp_path):
    foreign = tmp_path / "family.zarr"
    foreign.mkdir()
    (foreign / "precious.txt").write_text("keep me")
    fam = librate.dro_family("earth-moon", x0=[0.9, 0.85])
    with pytest.raises(FileExistsError, match="refusing to overwrite"):
        save_family(fam, foreign)
    assert (foreign / "precious.txt").read_text() == "keep me"
    with pytest.raises(ValueError, match="not a Zarr store"):
        librate.open_result(foreign)
    import xarray as xr

    other = tmp_path / "other.nc"
    xr.Dataset({"a": ("x", [1.0, 2.0])}).to_netcdf(other, engine="scipy")
    with pytest.raises(ValueError, match="not a librate result"):
        librate.open_result(other)
    with pytest.raises(FileExistsError):
        save_dataset(xr.Dataset({"a": ("x", [3.0])}), other)
    with pytest.raises(FileNotFoundError):
        librate.open_result(tmp_path / "nothing.zarr")
    # a result replaces a result, leaving no temporary behind
    p = save_family(fam, tmp_path / "f.nc")
    save_family(fam, p)
    assert sorted(x.name for x in tmp_path.iterdir()) == ["f.nc", "family.zarr", "other.nc"]


def test_members_outside_the_family_name_the_key_and_the_range():
    st = Study.from_dict({"orbits": {"kind": "dro", "period_days": [12.66, 100.0]}})
    with pytest.raises(StudyError) as info:
        st.build_orbits()
    (msg,) = info.value.problems
    assert msg.startswith("orbits.period_days = [12.66, 100.0]: no member at 100 on the dro family")
    assert "allowed: periods (days) from 0.03" in msg and "to 27.3" in msg


def test_the_stored_study_writes_the_defaults_out():
    d = Study.from_dict({"orbits": {"kind": "halo"}}).to_dict()
    assert d["system"] == {"preset": "earth-moon"}
    assert (d["orbits"]["point"], d["orbits"]["branch"], d["solver"]["n_periods"]) == (2, "south", 1)
    assert d["output"] == {"folder": "librate-out", "format": "zarr"} and d["torques"] == {"gravity_gradient": ["earth", "moon"]}


def test_a_map_is_exported_to_netcdf_too(tmp_path, base, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "librate.app.runner", None)
    st = Study.from_dict(edit(edit(base, "output.format", "netcdf"), "body.kz", [0.5, 0.8]), purpose="map")
    ds, path = run_map(st, tmp_path)
    nc = librate.open_result(tmp_path / "map.nc")
    zr = librate.open_result(path)
    assert nc.attrs["study"] == zr.attrs["study"] == st.to_json()
    assert nc["kz"].values.tolist() == [0.5, 0.8]
    for v in ("dwz", "dphi", "phi_T", "sol_wz0", "sol_kz"):
        assert np.array_equal(nc[v].values, zr[v].values, equal_nan=True), v
    assert nc["sol_stable"].values.astype(bool).tolist() == zr["sol_stable"].values.tolist()


def _flex_study(tmp_path, flexible, purpose="solve"):
    from librate.app.study import Study

    d = {"orbits": {"kind": "dro", "x0": [0.8, 0.75]}, "body": {"flexible": flexible},
         "rates": {"wz0": {"start": -2.0, "stop": 1.5, "num": 200}}}
    return Study.from_dict(d, purpose=purpose, base_dir=tmp_path)


def test_flexible_body_in_a_study(tmp_path):
    """Issue 8: studies accept a flexible body (preset or TOML file). `solve` finds the rigid
    solutions of the composite body and reports each one's first-order shift from flexibility
    (docs/physics.md, flexible spacecraft): negligible for the real-scale station (0.1 Hz arrays: < 1e-9), large for
    its low-frequency variant (> 1e-4 rad/TU somewhere)."""
    real, _ = run_solve(_flex_study(tmp_path, "sample-station"), out=tmp_path / "real")
    low, _ = run_solve(_flex_study(tmp_path, "sample-station-low-frequency"), out=tmp_path / "low")
    assert real.sizes["solution"] > 0 and real.flex_dwz0.attrs["units"] == "1/TU"
    assert np.max(np.abs(real.flex_dwz0.values)) < 1e-9
    assert np.max(np.abs(low.flex_dwz0.values)) > 1e-4
    # the composite body's Kz is thesis Table 3's 0.8; a FlexibleBody TOML file gives the same
    (tmp_path / "station.toml").write_text(librate.FlexibleBody.sample_station().to_toml())
    st = _flex_study(tmp_path, "station.toml")
    assert st.kz_values()[0] == pytest.approx(0.8, abs=1e-3)
    assert st.kz_values()[0] == _flex_study(tmp_path, "sample-station").kz_values()[0]


@pytest.mark.parametrize("body, key", [
    ({"flexible": "sample-station", "kz": 0.8}, "body.kz"),
    ({"flexible": "tower"}, "body.flexible"),
])
def test_flexible_body_errors(body, key):
    from librate.app.study import Study, StudyError

    d = {"orbits": {"kind": "dro", "x0": [0.8]}, "body": body, "rates": {"wz0": {"start": -2.0, "stop": 1.5, "num": 20}}}
    with pytest.raises(StudyError) as info:
        Study.from_dict(d, purpose="solve")
    assert len(info.value.problems) == 1 and info.value.problems[0].startswith(key)


def test_flexible_body_cannot_be_mapped(tmp_path):
    from librate.app.study import StudyError

    with pytest.raises(StudyError) as info:
        _flex_study(tmp_path, "sample-station", purpose="map")
    assert info.value.problems[0].startswith("body.flexible") and "solve" in info.value.problems[0]


def test_study_changes_names_the_keys_a_result_depends_on():
    """What `librate map` prints when it refuses a result of other inputs (issue 14): the dotted
    keys that differ, tables flattened, only the sections the result depends on."""
    from librate.app.results import RESULT_INPUTS, study_changes

    a = Study.from_dict({"orbits": {"kind": "dro", "x0": {"start": 0.9, "stop": 0.5, "num": 3}}, "body": {"kz": 0.8}}).to_json()
    b = Study.from_dict({"orbits": {"kind": "dro", "x0": {"start": 0.9, "stop": 0.5, "num": 4}}, "body": {"kz": 0.5},
                         "output": {"folder": "elsewhere"}}).to_json()
    assert study_changes(a, a) == []
    assert study_changes(a, b, RESULT_INPUTS["map"]) == ["body.kz: 0.8 -> 0.5", "orbits.x0.num: 3 -> 4"]
    assert study_changes(a, b, RESULT_INPUTS["family"]) == ["orbits.x0.num: 3 -> 4"]  # the body does not change a family
    assert 'output.folder: "librate-out" -> "elsewhere"' in study_changes(a, b)
    assert study_changes(None, a) == ["(study): none recorded in the existing result"]


# --- giant studies (issue 24 #7) ---------------------------------------------------------------
def _giant(kz_num: int, wz_num: int, x0_num: int = 12) -> dict:
    return {"orbits": {"x0": {"start": 0.9, "stop": 0.3, "num": x0_num}}, "body": {"kz": {"start": -1.0, "stop": 1.0, "num": kz_num}},
            "rates": {"wz0": {"start": -3.0, "stop": 2.0, "num": wz_num}}}


def test_giant_map_is_refused_naming_the_keys_before_any_allocation():
    """1000 Kz x 1e6 rates x 12 orbits: 1.2e10 trajectories and ~556 GB of map memory (the
    result arrays, 25 bytes a cell, and the row in flight, 256 bytes a case of one orbit's row:
    librate._checks.map_bytes, the estimate the API refuses by too), refused by the schema with
    a StudyError naming the keys, never a MemoryError."""
    from librate._checks import MAP_CELL_BYTES, MAP_ROW_CELL_BYTES, map_bytes
    from librate.app.budget import MAX_MAP_BYTES, MAX_WORK

    assert (MAP_CELL_BYTES, MAP_ROW_CELL_BYTES) == (3 * 8 + 1, 256)
    with pytest.raises(StudyError) as e:
        Study.from_dict(_giant(1000, 1_000_000), purpose="map")
    (msg,) = e.value.problems
    for text in ("orbits.x0 = 12 values", "body.kz = 1,000 values", "rates.wz0 = 1,000,000 values", "12,000,000,000 trajectories",
                 f"limit of {MAX_WORK:.3g}", "556 GB", "--force"):
        assert text in msg, (text, msg)
    assert map_bytes(12, 10**9) == 12e9 * 25 + 1e9 * 256 > MAX_MAP_BYTES
    # force=True lifts the limit: the study validates (nothing is allocated by validation)
    st = Study.from_dict(_giant(1000, 1_000_000), purpose="map", force=True)
    est = st.estimate("map")
    assert est.trajectories == 12_000_000_000 and est.bytes == 12_000_000_000 * 25 + 10**9 * 256
    with pytest.raises(StudyError, match="too large"):
        st.check("map")
    assert st.check("map", force=True) is not None
    # a solve of the same grid is refused for its work (no map arrays)
    with pytest.raises(StudyError, match="trajectory-periods exceed"):
        Study.from_dict(_giant(1000, 1_000_000), purpose="solve")


def test_a_study_within_its_budget_is_not_refused_by_the_engine():
    """The study's budget and the API's refusal of a map (librate._checks.check_map_cells, the
    guard of periodicity_map) are one estimate (map_bytes): a map study 1% under the 2 GiB limit
    passes both, 1% over is refused by both (before, the budget counted 25 bytes a cell and the
    API 57, so a study could pass its budget and then fail in the engine)."""
    from librate._checks import MAP_CELL_BYTES, MAP_ROW_CELL_BYTES, MAX_ARRAY_BYTES, check_map_cells

    for scale, refused in ((0.99, False), (1.01, True)):
        nw = int(scale * MAX_ARRAY_BYTES / (12 * 10 * MAP_CELL_BYTES + 10 * MAP_ROW_CELL_BYTES))
        data = {**_giant(10, nw), "solver": {"n_periods": 1}}
        if refused:
            with pytest.raises(StudyError, match="the map's memory .* exceeds the limit of 2.15 GB"):
                Study.from_dict(data, purpose="map")
            with pytest.raises(ValueError, match=r"invalid arguments `orbits`, `kz`, `wz0`: .* \(limit 2.15 GB\)"):
                check_map_cells((12, 10, nw), "`orbits`, `kz`, `wz0`")
        else:
            assert Study.from_dict(data, purpose="map", force=True).estimate("map").bytes <= MAX_ARRAY_BYTES
            assert check_map_cells((12, 10, nw), "`orbits`, `kz`, `wz0`") == 12 * 10 * nw


def test_ordinary_studies_pass_and_grid_sizes_are_bounded():
    """The example study (12 orbits x 1 Kz x 300 rates) is far within the limits; every grid is
    bounded at 1e6 values (a table's num and a list's length)."""
    st = Study.from_dict(_giant(1, 300), purpose="map")
    est = st.estimate("map")
    assert est.trajectories == 3600 and est.periods == 1 and est.bytes == 3600 * 25 + 300 * 256  # results and the row in flight
    assert "3,600 trajectories" in est.text()
    with pytest.raises(StudyError, match=r"rates\.wz0\.num = 2000000: .*1000000"):
        Study.from_dict(_giant(1, 2_000_000), purpose="map")
    with pytest.raises(StudyError, match=r"body\.kz = .*at most 1000000"):
        Study.from_dict({**_giant(1, 300), "body": {"kz": [0.5] * 1_000_001}})
    # n_periods counts in the work: 1000 periods of 1e6 trajectories is past the limit
    data = {**_giant(1, 100_000, 10), "solver": {"n_periods": 1000}}
    with pytest.raises(StudyError, match="1e\\+09 trajectory-periods"):
        Study.from_dict(data, purpose="map")
