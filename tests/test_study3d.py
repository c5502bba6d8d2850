"""Studies in the 3-D attitude model (issue 15, item 6): ``[attitude] model = "3d"``.

Validation: every problem names the key (dotted), the value given and what is allowed, as the
rules on the schema's fields (their descriptions) and ``_check_3d`` state (the reference for the error
paths). ``librate solve`` end to end on examples/study_3d_dro.toml (three DROs) and on a short
L2 southern halo family, the result re-opened and checked:

- every stored motion re-propagates (``librate.propagate_attitude``, rtol = atol = 1e-13) to
  closure <= 1e-9 (issue 15's re-propagation acceptance), and the stored residual is <= 1e-9;
- the multipliers come in reciprocal pairs to 1e-8 (issue 15, symplectic structure);
- the planar embedding: the first member's 3-D motion is the planar solve's N = -1 solution,
  wz0 equal to 1e-10, q0 a rotation about Z and w0 along z (issue 15 acceptance, thesis Fig. 23).
"""

import json
import math
from pathlib import Path

import librate
import numpy as np
import pytest

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib
from helpers import edit
from hypothesis import given, settings
from hypothesis import strategies as st
from librate.app.jobs import run_map, run_solve
from librate.app.results import multipliers_3d, solution_3d
from librate.app.study import Study, StudyError
from scipy.spatial.transform import Rotation

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "study_3d_dro.toml"
MOMENTS = {"ix": 12.12e6, "iy": 89.68e6, "iz": 96.95e6}  # thesis Table 3's station, Kz = 0.8


def base_study() -> dict:
    """A valid 3-D study: three DROs, the station's inertia, the planar N = -1 start."""
    return {"orbits": {"kind": "dro", "x0": [0.85, 0.83, 0.8]}, "body": dict(MOMENTS), "attitude": {"model": "3d", "n": -1},
            "rates": {"wz0": {"start": -3.0, "stop": 2.0, "num": 300}}}


@pytest.fixture
def base() -> dict:
    return base_study()




def problems_of(data: dict, purpose=None) -> list[str]:
    try:
        Study.from_dict(data, purpose=purpose)
    except StudyError as err:
        return err.problems
    return []


# --- the model and the defaults ----------------------------------------------------------------------
def test_the_planar_model_is_the_default_and_leaves_the_stored_study_unchanged(base):
    planar = edit(edit(base, "attitude"), "body", {"kz": 0.8})
    a = Study.from_dict(planar, purpose="solve")
    b = Study.from_dict(edit(planar, "attitude", {"model": "planar"}), purpose="solve")
    assert a.attitude.model == "planar" and a.attitude_start() is None
    assert "attitude" not in a.to_dict() and a.to_json() == b.to_json()


def test_the_start_is_written_out_and_inferred(base):
    st3 = Study.from_dict(base, purpose="solve")
    d = st3.to_dict()
    assert d["attitude"] == {"model": "3d", "n": -1, "start": "planar", "tol": 1e-12}
    assert Study.from_json(st3.to_json()).to_dict() == d
    halo = {"orbits": {"kind": "halo", "period_days": [14.0, 13.8]}, "body": dict(MOMENTS), "attitude": {"model": "3d", "n": 0}}
    assert Study.from_dict(halo, purpose="solve").attitude_start() == "spin"  # no [rates] needed
    given_ = edit(edit(base, "attitude.n"), "attitude.w0", [0.0, 0.0, -1.79])
    assert Study.from_dict(given_, purpose="solve").attitude_start() == "given"


def test_halo_families_are_valid_3d_studies_for_solve_and_map():
    halo = {"orbits": {"kind": "halo", "point": 1, "branch": "north", "members": 4}, "body": dict(MOMENTS),
            "attitude": {"model": "3d", "start": "spin", "n": 0, "q0": [0.0, 0.0, 0.0, 1.0]},
            "rates": {"wx0": {"start": -0.5, "stop": 0.5, "num": 11}, "wy0": 0.0, "wz0": [0.5, 1.0, 1.5]}}
    for purpose in (None, "family", "solve", "map"):
        Study.from_dict(halo, purpose=purpose)
    st3 = Study.from_dict(halo, purpose="map")
    r = st3.rates_3d()
    assert r["wy0"].tolist() == [0.0] and r["wz0"].tolist() == [0.5, 1.0, 1.5] and r["wx0"].size == 11
    assert st3.q0_3d().tolist() == [0.0, 0.0, 0.0, 1.0]
    # phidot0 stands for wz0 - 1
    rel = edit(edit(edit(halo, "rates.wz0"), "rates.phidot0", 0.25), "rates.wy0", [0.0, 0.1])
    assert Study.from_dict(rel, purpose="map").rates_3d()["wz0"].tolist() == [1.25]


# --- every error path ------------------------------------------------------------------------------------
# (change to the valid 3-D study, purpose, key named, value shown (None: missing), what is allowed, extra text)
CASES = [
    # the body: the full inertia, rigid
    ({"body": {"kz": 0.8}}, None, "body.kz", "0.8", "body.ix, body.iy and body.iz in kg m^2", "full inertia"),
    ({"body": {"kz": [0.5, 0.8]}}, "solve", "body.kz", "[0.5, 0.8]", "body.ix, body.iy and body.iz", "not Kz alone"),
    ({"body": {"flexible": "sample-station"}}, None, "body.flexible", '"sample-station"',
     "body.ix, body.iy and body.iz", "not modelled in 3-D"),
    ({"body": ...}, "solve", "body", None, None, "principal moments"),
    # torques
    ({"torques.srp": {"eps": 0.01}}, "solve", "torques.srp", '"[torques.srp]"',
     "no [torques.srp] with attitude.model = '3d'", "not modelled in 3-D"),
    ({"torques.gravity_gradient": ["moon"]}, None, "torques.gravity_gradient", '["moon"]', '["earth", "moon"]', "both primaries"),
    # [attitude] types and ranges
    ({"attitude.model": "4d"}, None, "attitude.model", '"4d"', "'planar' (the default", None),
    ({"attitude.start": "tumble"}, None, "attitude.start", '"tumble"', "'planar' (the planar N-family", None),
    ({"attitude.n": 200}, None, "attitude.n", "200", "an integer in [-100, 100]", None),
    ({"attitude.n": 1.5}, None, "attitude.n", "1.5", "an integer in [-100, 100]", None),
    ({"attitude.tol": 1e-3}, None, "attitude.tol", "0.001", "a number in [1e-14, 1e-6]", None),
    ({"attitude.colour": 1}, None, "attitude.colour", "1", None, "unknown key; allowed keys in [attitude]: model, start, n, q0, w0, tol"),
    ({"attitude.start": "given", "attitude.n": ..., "attitude.w0": [0.0, 1.0]}, None, "attitude.w0", "[0.0, 1.0]", "three numbers", None),
    # [attitude] combinations
    ({"attitude.n": ...}, None, "attitude.n", None, "an integer in [-100, 100]", "missing"),
    ({"attitude.q0": [0.0, 0.0, 0.0, 1.0]}, None, "attitude.q0", "[0.0, 0.0, 0.0, 1.0]", "attitude.start = 'given'",
     'attitude.start = "planar"'),
    ({"attitude.start": "spin", "attitude.w0": [0.0, 0.0, 1.0]}, None, "attitude.w0", "[0.0, 0.0, 1.0]",
     "attitude.start = 'given'", "spin"),
    ({"attitude.start": "given", "attitude.n": ...}, None, "attitude.w0", None, "three numbers", "missing"),
    ({"attitude.start": "given", "attitude.w0": [0.0, 0.0, 1.0]}, None, "attitude.n", "-1",
     "attitude.start = 'planar' or 'spin'", "does not apply"),
    ({"attitude.start": "spin", "attitude.q0": [0.0, 0.0, 0.0, 2.0]}, None, "attitude.q0", "[0.0, 0.0, 0.0, 2.0]",
     "a unit quaternion", "|q0| = 2"),
    ({"attitude.start": "spin", "attitude.q0": [0.0, 0.0, 0.0, 1.0], "solver.phi0": 0.5}, None, "solver.phi0", "0.5", "not both", None),
    ({"orbits": {"kind": "halo"}, "attitude.start": "planar"}, None, "attitude.start", '"planar"',
     "'spin' or 'given' on a halo family", "planar family"),
    ({"attitude": {"n": 1}}, None, "attitude.n", "1", "attitude.model = '3d'", "applies only"),
    # what `solve` needs
    ({"rates": ...}, "solve", "rates", None, None, "planar start scans"),
    ({"rates.wz0": 0.5}, "solve", "rates.wz0", "0.5", "strictly increasing", "not one value"),
    # what `map` needs: two grids and one fixed rate
    ({"rates": ...}, "map", "rates", None, None, "two grids and one fixed number"),
    ({"rates.wx0": [0.0, 0.1]}, "map", "rates.wy0", None, "a number (fixed) or a grid", "missing"),
    ({"rates.wx0": [0.0, 0.1], "rates.wy0": [0.0, 0.1]}, "map", "rates.wz0", '{start = -3.0, stop = 2.0, num = 300}',
     "exactly one of", "given 0 fixed"),
    ({"rates.wx0": 0.0, "rates.wy0": 0.0}, "map", "rates.wy0", "0.0", "exactly one of", "given 2 fixed"),
    ({"rates.wx0": [0.1, 0.0], "rates.wy0": 0.0}, "map", "rates.wx0", "[0.1, 0.0]", "strictly increasing", None),
    # the planar model: no 3-D keys
    ({"attitude": ..., "body": {"kz": 0.8}, "rates.wx0": [0.0, 0.1]}, None, "rates.wx0", "[0.0, 0.1]",
     "[attitude] model = '3d'", "applies only"),
    ({"attitude": ..., "body": {"kz": 0.8}, "rates.wz0": 0.5}, None, "rates.wz0", "0.5", "strictly increasing", "at least 2 values"),
    ({"attitude": ..., "body": {"kz": 0.8}, "orbits": {"kind": "halo"}}, "map", "orbits.kind", '"halo"',
     "any family with [attitude] model = '3d'", "planar"),
]


@pytest.mark.parametrize("change, purpose, key, value, allowed, extra", CASES, ids=[c[2] + ":" + str(i) for i, c in enumerate(CASES)])
def test_each_3d_study_error_names_the_key_the_value_and_what_is_allowed(base, change, purpose, key, value, allowed, extra):
    data = base
    for k, v in change.items():
        data = edit(data, k, v)
    problems = problems_of(data, purpose)
    assert len(problems) == 1, problems  # one clear message per problem
    msg = problems[0]
    assert msg.startswith(f"{key}: " if value is None else f"{key} = {value}: "), msg
    if allowed is not None:
        assert "; allowed: " in msg and allowed in msg.split("; allowed: ", 1)[1], msg
    if extra is not None:
        assert extra in msg, msg


GRID = {"start": -0.5, "stop": 0.5, "num": 5}


@pytest.mark.parametrize("wx0, wy0, wz0", [(a, b, c) for a in (0.0, GRID) for b in (0.0, GRID) for c in (1.0, GRID)])
def test_a_3d_map_takes_exactly_two_grids_and_one_fixed_rate(base, wx0, wy0, wz0):
    """All eight grid/fixed patterns of (wx0, wy0, wz0): valid exactly when one is fixed;
    otherwise one problem naming a rate key and the rule."""
    data = edit(edit(edit(base, "rates.wx0", wx0), "rates.wy0", wy0), "rates.wz0", wz0)
    fixed = sum(isinstance(v, float) for v in (wx0, wy0, wz0))
    problems = problems_of(data, "map")
    if fixed == 1:
        assert problems == []
    else:
        assert (len(problems) == 1 and problems[0].startswith("rates.w")
            and "exactly one of rates.wx0, rates.wy0, rates.wz0" in problems[0]), problems


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-2.0, 2.0, allow_nan=False), min_size=4, max_size=4))
def test_q0_is_valid_exactly_when_it_is_a_unit_quaternion(q):
    """Property: any four numbers as attitude.q0 (start = "given"): valid when |q| is 1 to
    1e-6, else one problem naming attitude.q0, its value and |q0|."""
    data = edit(edit(edit(base_study(), "attitude.n"), "attitude.w0", [0.0, 0.0, 1.0]), "attitude.q0", q)
    problems = problems_of(data)
    norm = math.hypot(*q)
    if abs(norm - 1) <= 1e-6:
        assert problems == []
        assert np.linalg.norm(Study.from_dict(data).q0_3d()) == pytest.approx(1.0, abs=1e-15)
    else:
        assert len(problems) == 1 and problems[0].startswith("attitude.q0 = [") and "unit quaternion" in problems[0], problems


@settings(max_examples=40, deadline=None)
@given(st.sampled_from(["planar", "spin", "given"]), st.sampled_from(["dro", "lyapunov", "halo"]), st.booleans(),
       st.booleans(), st.booleans())
def test_every_start_combination_is_valid_or_names_its_keys(start, kind, with_n, with_q0, with_w0):
    """Property: for any start, family and set of attitude keys, the study is valid exactly when
    the rules of docs/cli.md hold, and every problem names an [attitude] key."""
    att = {"model": "3d", "start": start, **({"n": 1} if with_n else {}), **({"q0": [0.0, 0.0, 0.0, 1.0]} if with_q0 else {}),
           **({"w0": [0.0, 0.0, 1.0]} if with_w0 else {})}
    orbits = {"kind": kind, "members": 3}
    problems = problems_of({**base_study(), "orbits": orbits, "attitude": att})
    ok = {"planar": kind != "halo" and with_n and not with_q0 and not with_w0,
          "spin": with_n and not with_w0,
          "given": with_w0 and not with_n}[start]
    assert (problems == []) == ok, problems
    assert all(p.startswith("attitude.") for p in problems), problems


def test_the_example_3d_study_is_valid():
    data = tomllib.loads(EXAMPLE.read_text())
    st3 = Study.from_dict(data, purpose="solve")
    assert st3.attitude.model == "3d" and st3.attitude_start() == "planar" and st3.build_body().moments == (12.12e6, 89.68e6, 96.95e6)
    with pytest.raises(StudyError, match="rates.wx0: missing: a 3-D map needs"):
        Study.from_dict(data, purpose="map")


# --- librate solve end to end ------------------------------------------------------------------------


def reprop_closure(ds, j) -> tuple[float, float]:
    """Closure of member j re-propagated from the file alone: |rotation vector of R(0)' R(KT)|
    and |w(KT) - w0|, with librate.propagate_attitude at rtol = atol = 1e-13."""
    system = librate.System.preset(ds.attrs["system_name"])
    body = librate.RigidBody(*np.atleast_1d(ds.attrs["body_moments"]))
    q0, w0 = ds["q0"].values[j], ds["w0"].values[j]
    k = int(ds.attrs["n_periods"])
    tr = librate.propagate_attitude(system, ds["orbit_state0"].values[j], (q0, w0), body, k * float(ds["orbit_period"].values[j]),
                                    rtol=1e-13, atol=1e-13)
    rot = (Rotation.from_quat(q0).inv() * Rotation.from_quat(tr.q[-1])).as_rotvec()
    return float(np.linalg.norm(rot)), float(np.linalg.norm(tr.w[-1] - w0))


def check_stored_motions(ds):
    assert ds.attrs["librate_result"] == "solutions_3d" and ds.attrs["librate_command"] == "solve"
    assert ds.attrs["librate_version"] == librate.__version__
    assert ds["w0"].attrs["units"] == "1/TU" and ds["period_days"].attrs["units"] == "d" and ds["orbit_period"].attrs["units"] == "TU"
    assert np.all(ds["residual"].values <= 1e-9)
    for j in range(ds.sizes["member"]):
        d_rot, d_w = reprop_closure(ds, j)
        assert d_rot <= 1e-9 and d_w <= 1e-9, (j, d_rot, d_w)
        m = multipliers_3d(ds)[j]
        # reciprocal pairs: 1/lambda is a multiplier too (issue 15, symplectic structure, 1e-8)
        assert max(np.min(np.abs(m - 1 / lam)) for lam in m) <= 1e-8, m


def test_solve_a_3d_dro_study_embeds_the_planar_solution(cli, tmp_path):
    """examples/study_3d_dro.toml: the planar N = -1 motion on x0 = 0.85 (Kz = 0.8) taken into
    3-D and continued along three DROs. The first member is the planar solve's solution (wz0 to
    1e-10, q0 a rotation about Z, w0 along z); every member re-propagates from the file."""
    res = cli("solve", EXAMPLE, "--out", tmp_path / "d3")
    assert "periodic 3-D attitude motion along 3 of 3 member(s) of the dro family" in res.output
    assert "continuation: completed" in res.output
    path = tmp_path / "d3" / "solve.zarr"
    for fig in ("solve_multipliers.png", "solve_body_axes.png"):
        assert (tmp_path / "d3" / fig).stat().st_size > 0
    ds = librate.open_result(path)
    assert ds.sizes["member"] == 3 and ds["x0"].values.tolist() == pytest.approx([0.85, 0.83, 0.8], abs=1e-12)
    check_stored_motions(ds)
    st3 = Study.from_json(ds.attrs["study"])
    assert st3.to_dict() == Study.from_toml(EXAMPLE).to_dict()

    # the planar solve of the same DROs, rates and Kz (the body's (Iy - Ix) / Iz)
    planar = tomllib.loads(EXAMPLE.read_text())
    planar.pop("attitude")
    planar["body"] = {"kz": (MOMENTS["iy"] - MOMENTS["ix"]) / MOMENTS["iz"]}
    planar["output"] = {"format": "netcdf"}
    sols, _ = run_solve(Study.from_dict(planar, purpose="solve"), tmp_path / "p")
    sel = (sols["sol_orbit"].values == 0) & (sols["sol_n"].values == -1) & (sols["sol_kind"].values.astype(str) == "periodic")
    (wz_planar,) = sols["sol_wz0"].values[sel]
    q0, w0 = ds["q0"].values[0], ds["w0"].values[0]
    assert abs(w0[2] - wz_planar) <= 1e-10
    assert ds.attrs["start"] == "planar" and ds.attrs["start_planar_wz0"] == wz_planar
    assert np.all(np.abs(q0[:2]) <= 1e-10) and np.all(np.abs(w0[:2]) <= 1e-10)
    assert ds["turns"].values.tolist() == pytest.approx([-1.0] * 3, abs=1e-9)  # N = -1: one turn backwards per period

    # re-running reuses the result; `librate plot` re-draws both figures from the file
    again = cli("solve", EXAMPLE, "--out", tmp_path / "d3")
    assert "reused" in again.stderr
    for fig in ("solve_multipliers.png", "solve_body_axes.png"):
        (tmp_path / "d3" / fig).unlink()
    cli("plot", path)
    assert (tmp_path / "d3" / "solve_multipliers.png").exists() and (tmp_path / "d3" / "solve_body_axes.png").exists()
    # the first member, corrected again from the file, is the stored one
    s = solution_3d(ds, 0)
    assert np.max(np.abs(s.w0 - w0)) <= 1e-10 and s.residual <= 1e-9


def test_solve_a_3d_halo_study_from_the_torque_free_spin(cli, tmp_path):
    """The body 0.8 : 0.9 : 1 on four L2 southern halos (14 to 11 days), started from the
    torque-free spin n = -1 (wz0 = 1 - 2 pi / T about synodic Z), as in tests/test_attitude3d.py's
    NRHO family: netCDF result, every member re-propagates from the file, and the continuation
    locates a stability change (a Krein collision between 12 and 11 days, test function zero to
    1e-8 in the period), printed and stored."""
    import ast

    study = tmp_path / "halo.toml"
    study.write_text(
        '[orbits]\nkind = "halo"\npoint = 2\nbranch = "south"\nperiod_days = [14.0, 13.0, 12.0, 11.0]\n'
        '[body]\nix = 0.8\niy = 0.9\niz = 1.0\n[attitude]\nmodel = "3d"\nn = -1\n[output]\nformat = "netcdf"\nfigures = ["multipliers"]\n')
    res = cli("solve", study)
    ds = librate.open_result(tmp_path / "librate-out" / "solve.nc")
    t14 = librate.System.preset("earth-moon").from_days(14.0)
    assert ds.attrs["start"] == "spin" and ds.attrs["start_w0"] == pytest.approx([0.0, 0.0, 1 - 2 * math.pi / t14], abs=1e-12)
    assert ds["period_days"].values.tolist() == pytest.approx([14.0, 13.0, 12.0, 11.0], abs=1e-9)
    assert np.all(ds["z0"].values < 0)  # the southern branch
    check_stored_motions(ds)
    assert json.loads(ds.attrs["study"])["attitude"]["start"] == "spin"
    (change,) = ast.literal_eval(ds.attrs["stability_changes"])
    assert (change["kind"] == "krein" and change["located"] and 11.0 < change["at"] < 12.0
            and change["between"] == pytest.approx((12.0, 11.0)))
    assert f"stability change (krein) at T = {change['at']:.10g} d" in res.output
    assert (tmp_path / "librate-out" / "solve_multipliers.png").exists() and not (tmp_path / "librate-out" / "solve_body_axes.png").exists()


def map_3d_study(tmp_path) -> Path:
    """The example 3-D study with a 3-D map's rates: wx0 a grid (21), wy0 = 0, wz0 a grid (60)."""
    study = tmp_path / "m.toml"
    text = EXAMPLE.read_text().replace("# wx0 = {", "wx0 = {").replace("# wy0 = 0.0", "wy0 = 0.0")
    study.write_text(text.replace("num = 101", "num = 21").replace("num = 300", "num = 60"))
    return study


def test_map_of_a_3d_study(cli, tmp_path):
    """`librate map` on a 3-D study: the six residuals over (orbit, wx0, wz0) of the 3-D map
    engine, written to map.zarr (a part store) with the study, a summary line per
    orbit and the residual figure. Reference: the planar embedding (the body's z on synodic Z,
    wx0 = wy0 = 0) is a planar motion, so rx, ry, dwx, dwy vanish there exactly; and each orbit's
    map equals librate.attitude_map_3d on that orbit (bit for bit: the same engine and grid)."""
    study = map_3d_study(tmp_path)
    res = cli("map", study)
    assert "3-D attitude map: 3 orbits x 21 wx0 x 60 wz0 = 3780 trajectories" in res.output
    assert res.output.count("smallest max |residual|") == 3
    path = tmp_path / "librate-out" / "map.zarr"
    ds = librate.open_result(path, verify=True)
    assert ds.attrs["librate_result"] == "map_3d" and ds.attrs["librate_command"] == "map" and int(ds.attrs["complete"]) == 1
    assert ds["residual"].dims == ("orbit", "wx0", "wz0", "component") and float(ds["wy0"]) == 0.0
    assert ds["status"].dtype == np.uint8 and "done" not in ds.variables
    j = int(np.argmin(np.abs(ds["wx0"].values)))
    assert ds["wx0"].values[j] == 0.0
    planar = ds["residual"].isel(wx0=j).sel(component=["rx", "ry", "dwx", "dwy"]).values
    assert np.all(planar == 0.0)
    st3 = Study.from_toml(study)
    alone = librate.attitude_map_3d(st3.build_orbits()[1], st3.build_body(), wx0=ds["wx0"].values, wy0=0.0, wz0=ds["wz0"].values,
                                    tol=float(ds.attrs["tol"]))
    np.testing.assert_array_equal(alone["residual"].values, ds["residual"].isel(orbit=1).values)
    # re-running reuses it; `librate plot` draws the residual map
    again = cli("map", study)
    assert "3-D attitude map" in again.output
    cli("plot", path)
    assert (tmp_path / "librate-out" / "map_residual_norm.png").stat().st_size > 0
    # an invalid 3-D map study is refused first (exit 2), listing the problem
    res = cli("map", EXAMPLE, "--out", tmp_path / "x", code=2)
    assert "rates.wx0: missing" in res.output


def test_an_interrupted_3d_map_keeps_its_finished_orbits(tmp_path, monkeypatch):
    """A 3-D map stopped in its second orbit keeps the first (its part committed with a checksum):
    the same run again computes only the two others, and the result equals an uninterrupted run
    bit for bit. A damaged part (its bytes overwritten) is named in a warning and recomputed."""
    import librate.periodicity.map3d as m3

    study = Study.from_toml(map_3d_study(tmp_path))
    real, calls = m3.attitude_map_3d, []

    def stop_second(orbit, *args, **kw):
        calls.append(orbit.period_days)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(orbit, *args, **kw)

    monkeypatch.setattr(m3, "attitude_map_3d", stop_second)
    with pytest.raises(KeyboardInterrupt):
        run_map(study, tmp_path / "a", progress=False)
    from librate.results import verify_store

    rep = verify_store(tmp_path / "a" / "map.zarr")  # the part store: orbit 0 done, 1 and 2 not
    assert rep.not_done == [1, 2] and not rep.damaged and not rep.complete
    calls.clear()
    monkeypatch.setattr(m3, "attitude_map_3d", lambda orbit, *a, **k: calls.append(orbit.period_days) or real(orbit, *a, **k))
    ds, _ = run_map(study, tmp_path / "a", progress=False)
    assert len(calls) == 2  # the finished first orbit was reused
    whole, _ = run_map(study, tmp_path / "b", progress=False)
    np.testing.assert_array_equal(ds["residual"].values, whole["residual"].values)
    # damage: a part whose bytes changed is detected by its checksums and recomputed
    monkeypatch.setattr(m3, "attitude_map_3d", stop_second)
    calls.clear()
    with pytest.raises(KeyboardInterrupt):
        run_map(study, tmp_path / "c", progress=False)
    part = tmp_path / "c" / "map.zarr" / "residual" / "0.0.0.0"  # orbit 0's residuals
    raw = bytearray(part.read_bytes())
    raw[-64:] = b"\x00" * 64
    part.write_bytes(bytes(raw))
    monkeypatch.setattr(m3, "attitude_map_3d", real)
    with pytest.warns(RuntimeWarning, match="damaged orbit\\(s\\) are recomputed: orbit 0: chunk residual/0.0.0.0"):
        ds_c, _ = run_map(study, tmp_path / "c", progress=False)
    np.testing.assert_array_equal(ds_c["residual"].values, whole["residual"].values)


def test_solve_3d_reports_progress_per_member(tmp_path):
    """``progress(done, total)`` after each requested member reached, as the planar solve."""
    calls = []
    st3 = Study.from_dict({"orbits": {"kind": "halo", "period_days": [14.0, 13.9]}, "body": {"ix": 1.0, "iy": 1.02, "iz": 1.04},
                           "attitude": {"model": "3d", "n": 0}}, purpose="solve")
    ds, path = run_solve(st3, tmp_path, progress=lambda done, total: calls.append((done, total)))
    assert calls == [(1, 2), (2, 2)] and ds.sizes["member"] == 2 and path.name == "solve.zarr"


def test_solve_a_3d_study_of_one_orbit(cli, tmp_path):
    """A study selecting one orbit (x0 = 0.85) solves the 3-D motion on it alone: a one-member
    result, "no continuation", the same motion as the first member of the three-member example
    (wz0 and q0 to 1e-10: the same start and corrector), re-propagating from the file to 1e-9."""
    one = tomllib.loads(EXAMPLE.read_text())
    one["orbits"]["x0"] = [0.85]
    one["output"] = {"format": "netcdf"}
    ds, path = run_solve(Study.from_dict(one, purpose="solve"), tmp_path / "one")
    assert ds.sizes["member"] == 1 and "no continuation" in ds.attrs["end_reason"]
    check_stored_motions(librate.open_result(path))
    three, _ = run_solve(Study.from_toml(EXAMPLE), tmp_path / "three")
    assert np.max(np.abs(ds["w0"].values[0] - three["w0"].values[0])) <= 1e-10
    assert np.max(np.abs(ds["q0"].values[0] - three["q0"].values[0])) <= 1e-10
