"""A CR3BP periodic attitude motion carried into the Earth-Moon-Sun ephemeris model.

:func:`attitude_to_ephemeris` places a periodic attitude solution (planar or 3-D, any number of
turns) along an ephemeris orbit (:func:`librate.to_ephemeris`), propagates it in the ephemeris
model, and corrects it by multiple shooting into a continuous motion: the motion's ephemeris
counterpart. The model and the corrector run in Rust (``librate._core.EphemerisAttitudeModel``):

- the state is the Moon-centred ICRF orbit (km, km/s), the quaternion of the body relative to
  ICRF (scalar last, v_icrf = R(q) v_body) and the inertial angular velocity in body axes
  (rad/s); the torques are the gravity gradients of the Earth, the Moon and the Sun from the
  ephemeris and, for a :class:`~librate.FacetBody`, solar radiation pressure with the ephemeris
  Sun direction, the pressure scaled by (1 AU / r)^2, and the eclipses by the Earth and the Moon
  (conical shadow with penumbra);
- placement: at an epoch, the CR3BP attitude relative to the synodic frame becomes one relative
  to the instantaneous Earth-Moon frame, and its rate relative to that frame is scaled from 1/TU
  to rad/s with the instantaneous rotation rate, then the frame's own angular velocity is added;
- the CR3BP time of an epoch: the orbit's nodes are at equal CR3BP time steps, T /
  nodes_per_rev apart from t = 0 at the first node, and between nodes the CR3BP time runs
  linearly with the epoch;
- the deviation from the CR3BP motion at an epoch: the ephemeris attitude taken back into the
  instantaneous rotating frame against the CR3BP attitude at the CR3BP time: the angle between
  each body axis in the two (degrees), and the rate error |w - w_ref| / |w_ref|, with w_ref the
  CR3BP rate placed at that epoch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._checks import as_count, as_tolerance
from .._errors import ConvergenceError
from ..attitude.body import RigidBody
from ..attitude.propagate import propagate_attitude
from ..attitude.srp import FacetBody
from ..ephemeris.model import Ephemeris, propagate_ephemeris
from .periodic_attitude3d import AttitudeSolution3D
from .solutions import AttitudeSolution

__all__ = ["EphemerisAttitude", "attitude_to_ephemeris"]

#: The corrected motion's continuity goal: rotation (rad) and relative rate.
CONTINUITY_RAD = 1e-6
CONTINUITY_RATE = 1e-6


@dataclass(frozen=True)
class EphemerisAttitude:
    """An attitude motion along an ephemeris orbit, placed from a CR3BP periodic solution and
    (``corrected``) made continuous by multiple shooting. Made by :func:`attitude_to_ephemeris`.

    Attributes
    ----------
    solution : AttitudeSolution or AttitudeSolution3D
        The CR3BP motion.
    ephemeris_orbit : EphemerisOrbit
        The orbit it is carried along.
    body : RigidBody
        The body (a `FacetBody` when solar radiation pressure acts).
    epochs_tdb : numpy.ndarray, shape (n,)
        Attitude node epochs, TDB s past J2000, within the orbit's span.
    q : numpy.ndarray, shape (n, 4)
        Scalar last, body -> ICRF: v_icrf = R(q) v_body.
    w : numpy.ndarray, shape (n, 3)
        Inertial angular velocity in body axes, rad/s.
    orbit_states_km : numpy.ndarray, shape (n, 6)
        The orbit at the nodes (Moon-centred ICRF, km, km/s).
    corrected : bool
        Corrected by multiple shooting (else the placed node attitudes).
    iterations : int
        Newton iterations.
    reason : str
        The corrector's stop reason.
    defect_rad, defect_rate : numpy.ndarray, shape (n - 1,)
        Each leg's mismatch at the next node, from a fresh propagation of the legs: the rotation
        angle (rad) and |dw| / |w|.
    monodromy : numpy.ndarray, shape (6, 6)
        d(theta, w)(end) / d(theta, w)(start) over the span (theta a small rotation in body
        axes; rad and rad/s).
    t_tdb : numpy.ndarray, shape (m,)
        Sample epochs of the deviation figures.
    revolution : numpy.ndarray, shape (m,)
        The orbit revolution of each sample (from 0).
    pointing_error_deg : numpy.ndarray, shape (m, 3)
        Angle between each body axis of this motion and of the CR3BP motion (module docs).
    rate_error : numpy.ndarray, shape (m,)
        |w - w_ref| / |w_ref|, w_ref the CR3BP rate placed at the epoch.
    placed_pointing_error_deg, placed_rate_error : numpy.ndarray
        The same for the placed motion propagated from the first node without correction.
    q_rotating, q_rotating_cr3bp : numpy.ndarray, shape (m, 4)
        At the sample epochs, scalar last: this motion taken back into the instantaneous
        rotating frame, and the CR3BP motion (relative to the synodic frame) at the same CR3BP
        times (the two attitudes the pointing error compares; :meth:`angles_deg`).
    gravity_gradient : (bool, bool, bool)
        The gradients of the Earth, the Moon and the Sun.
    srp : bool
        Solar radiation pressure acted (a `FacetBody`).
    continuous : bool
        Every leg meets the next node within 1e-6 rad and 1e-6 relative in rate.
    multipliers, growth
        Eigenvalues of the span monodromy, and the largest modulus.
    """

    solution: object = field(repr=False)
    ephemeris_orbit: object = field(repr=False)
    body: RigidBody
    epochs_tdb: np.ndarray
    q: np.ndarray
    w: np.ndarray
    orbit_states_km: np.ndarray = field(repr=False)
    corrected: bool
    iterations: int
    reason: str
    defect_rad: np.ndarray = field(repr=False)
    defect_rate: np.ndarray = field(repr=False)
    monodromy: np.ndarray = field(repr=False)
    t_tdb: np.ndarray = field(repr=False)
    revolution: np.ndarray = field(repr=False)
    pointing_error_deg: np.ndarray = field(repr=False)
    rate_error: np.ndarray = field(repr=False)
    placed_pointing_error_deg: np.ndarray = field(repr=False)
    placed_rate_error: np.ndarray = field(repr=False)
    gravity_gradient: tuple = (True, True, True)
    srp: bool = False
    q_rotating: np.ndarray | None = field(default=None, repr=False)
    q_rotating_cr3bp: np.ndarray | None = field(default=None, repr=False)

    @property
    def max_defect_rad(self) -> float:
        return float(np.max(self.defect_rad))

    @property
    def max_defect_rate(self) -> float:
        return float(np.max(self.defect_rate))

    @property
    def continuous(self) -> bool:
        """Every leg meets the next node within 1e-6 rad and 1e-6 relative in rate."""
        return bool(self.max_defect_rad <= CONTINUITY_RAD and self.max_defect_rate <= CONTINUITY_RATE)

    @property
    def max_pointing_error_deg(self) -> float:
        return float(np.max(self.pointing_error_deg))

    @property
    def placed_max_pointing_error_deg(self) -> float:
        return float(np.max(self.placed_pointing_error_deg))

    def deviation_per_revolution_deg(self, placed: bool = False) -> np.ndarray:
        """The largest pointing error (any axis, degrees) in each orbit revolution: how the
        deviation grows."""
        err = (self.placed_pointing_error_deg if placed else self.pointing_error_deg).max(axis=1)
        n = int(self.revolution.max()) + 1
        return np.array([err[self.revolution == k].max() for k in range(n)])

    def angles_deg(self) -> tuple[np.ndarray, np.ndarray]:
        """The attitude angles at the sample epochs in both models, (m, 3) each, degrees:
        (CR3BP motion, this motion). Roll, pitch and yaw are the Euler angles of the body
        relative to the rotating frame, R = Rz(yaw) Ry(pitch) Rx(roll) (scipy's "ZYX"), with roll
        and yaw unwrapped along time (a turning motion's yaw runs on past 180 degrees); in the
        planar model yaw is phi and roll = pitch = 0."""
        from scipy.spatial.transform import Rotation

        def rpy(q) -> np.ndarray:
            ypr = Rotation.from_quat(np.asarray(q, dtype=float)).as_euler("ZYX")
            ypr[:, [0, 2]] = np.unwrap(ypr[:, [0, 2]], axis=0)
            return np.degrees(ypr[:, ::-1])

        return rpy(self.q_rotating_cr3bp), rpy(self.q_rotating)

    @property
    def multipliers(self) -> np.ndarray:
        """Eigenvalues of the span monodromy."""
        return np.linalg.eigvals(self.monodromy)

    @property
    def growth(self) -> float:
        """The largest |multiplier| over the span: above one, small attitude errors grow."""
        return float(np.max(np.abs(self.multipliers)))


def _cr3bp_reference(solution) -> tuple[RigidBody, np.ndarray, np.ndarray, int]:
    """(body, q0 relative to synodic, w0 1/TU, K) of a planar or 3-D solution."""
    if isinstance(solution, AttitudeSolution3D):
        return solution.body, np.asarray(solution.q0, dtype=float), np.asarray(solution.w0, dtype=float), int(solution.n_periods)
    if isinstance(solution, AttitudeSolution):
        if solution.srp is not None:
            raise ValueError("invalid argument `solution`: a planar solution with the flat-plate SRP model; pass a gravity-gradient "
                             "solution (the ephemeris model's SRP acts on the facets of a librate.FacetBody given as `body`)")
        if solution.kind != "periodic":
            raise ValueError("invalid argument `solution`: a half-turn solution repeats the attitude only up to a half "
                             "turn; pass a periodic one")
        h = 0.5 * solution.phi0
        return (RigidBody.from_kz(solution.kz), np.array([0.0, 0.0, math.sin(h), math.cos(h)]), np.array([0.0, 0.0, solution.wz0]),
                int(solution.n_periods))
    raise ValueError("invalid argument `solution`: must be a librate.AttitudeSolution or AttitudeSolution3D, got "
                     f"{type(solution).__name__}")


def _check_body(body, ref: RigidBody) -> RigidBody:
    if body is None:
        return ref
    if not isinstance(body, RigidBody):
        raise ValueError(f"invalid argument `body`: must be a librate.RigidBody or FacetBody, got {type(body).__name__}")
    a = np.array(body.moments, dtype=float)
    b = np.array(ref.moments, dtype=float)
    if np.max(np.abs(a / a[2] - b / b[2])) > 1e-9:
        raise ValueError(f"invalid argument `body`: its principal moments {tuple(a)} are not proportional to the solution's {tuple(b)}")
    return body


def _node_times(eo, per_leg: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Attitude node epochs, their CR3BP times (TU) and orbit states (km, km/s): each orbit leg
    split into ``per_leg`` equal sub-legs."""
    e = np.asarray(eo.epochs_tdb, dtype=float)
    s = np.asarray(eo.states_km, dtype=float)
    dt = eo.orbit.period / eo.nodes_per_rev
    epochs, taus, states = [], [], []
    for j in range(e.size - 1):
        offs = (e[j + 1] - e[j]) * np.arange(per_leg) / per_leg
        tr = propagate_ephemeris(s[j], e[j], offs[-1], ephemeris=eo.ephemeris, t_eval=offs) if per_leg > 1 else None
        for k in range(per_leg):
            epochs.append(e[j] + offs[k])
            taus.append(dt * (j + k / per_leg))
            states.append(s[j] if tr is None else tr.states_km[k])
    epochs.append(e[-1])
    taus.append(dt * (e.size - 1))
    states.append(s[-1])
    return np.array(epochs), np.array(taus), np.array(states)


def _reference_at(solution, body, q0, w0, k_periods, taus) -> tuple[np.ndarray, np.ndarray]:
    """The CR3BP attitude (q relative to synodic, w 1/TU) at CR3BP times ``taus`` (its period
    K T: at tau mod K T)."""
    orbit = solution.orbit
    span = k_periods * orbit.period
    uniq, inverse = np.unique(np.mod(taus, span), return_inverse=True)
    tr = propagate_attitude(orbit.system, orbit.state0, (q0, w0), body, span, t_eval=uniq, rtol=1e-13, atol=1e-13)
    return np.ascontiguousarray(tr.q[inverse]), np.ascontiguousarray(tr.w[inverse])


def _deviation(model, epochs, q, w, q_ref, w_ref) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pointing error of each body axis (deg) and relative rate error against the CR3BP motion,
    and the motion in the rotating frame (q, scalar last)."""
    from scipy.spatial.transform import Rotation

    q_s, _ = model.place(epochs, np.ascontiguousarray(q), np.ascontiguousarray(w), inverse=True)
    _, w_placed = model.place(epochs, np.ascontiguousarray(q_ref), np.ascontiguousarray(w_ref))
    a = Rotation.from_quat(q_s).as_matrix()  # body axes (columns) in the rotating frame
    b = Rotation.from_quat(q_ref).as_matrix()
    chord = np.linalg.norm(a - b, axis=1)  # |x_a - x_b| per body axis (column); angle 2 asin(chord / 2)
    err = np.degrees(2.0 * np.arcsin(np.clip(0.5 * chord, 0.0, 1.0)))
    rate = np.linalg.norm(w - w_placed, axis=1) / np.linalg.norm(w_placed, axis=1)
    return err, rate, np.asarray(q_s)


def _samples(epochs: np.ndarray, per_leg: int) -> np.ndarray:
    """Sample epochs: ``per_leg`` per leg, the nodes included."""
    pts = [epochs[i] + (epochs[i + 1] - epochs[i]) * np.arange(per_leg) / per_leg for i in range(epochs.size - 1)]
    return np.concatenate(pts + [epochs[-1:]])


def attitude_to_ephemeris(solution, ephemeris_orbit, *, correct: bool = True, body=None, gravity_gradient=(True, True, True),
                          eclipses: bool = True, nodes_per_leg: int = 1, samples_per_leg: int = 8, tol: float = 1e-9,
                          max_iter: int = 30, rtol: float = 1e-12, atol: float = 1e-15) -> EphemerisAttitude:
    """Carry a CR3BP periodic attitude motion into the ephemeris model along ``ephemeris_orbit``.

    Parameters
    ----------
    solution : AttitudeSolution or AttitudeSolution3D
        A periodic motion (gravity gradient) along ``ephemeris_orbit.orbit``.
    ephemeris_orbit : EphemerisOrbit
        From :func:`librate.to_ephemeris`: node epochs and continuous node states.
    correct : bool, default True
        Correct by multiple shooting (minimum-norm Newton from the placed motion) into a
        continuous motion; False keeps the placed node attitudes.
    body : RigidBody or FacetBody, optional
        The body, with principal moments proportional to the solution's (default the
        solution's). A `FacetBody` (inertia in kg m^2) adds solar radiation pressure on its
        facets.
    gravity_gradient : (bool, bool, bool)
        The gravity gradient of the Earth, the Moon and the Sun.
    eclipses : bool, default True
        With SRP: the eclipses by the Earth and the Moon.
    nodes_per_leg : int, default 1
        Attitude nodes per orbit leg (more for fast-spinning motions).
    samples_per_leg : int, default 8
        Sample epochs per attitude leg for the deviation figures.
    tol : float, default 1e-9
        Corrector tolerance on every defect (rad, and rate in units of the Earth-Moon rotation
        rate at the first node).
    max_iter : int, default 30
    rtol, atol : float
        Integration tolerances of the ephemeris attitude legs (atol is for every component, so it
        is set for the rates in rad/s).

    Returns
    -------
    EphemerisAttitude
        The nodes, the defects, the span monodromy and the deviation figures.

    Raises
    ------
    ConvergenceError
        The corrector stopped without meeting ``tol``; its reason is in the message.
    ValueError
        A bad argument, named.
    """
    ref_body, q0, w0, k_periods = _cr3bp_reference(solution)
    use_body = _check_body(body, ref_body)
    gg = tuple(bool(g) for g in gravity_gradient)
    if len(gg) != 3:
        raise ValueError(f"invalid argument `gravity_gradient`: must be 3 booleans (Earth, Moon, Sun), got {gravity_gradient!r}")
    nodes_per_leg = as_count(nodes_per_leg, "nodes_per_leg", 1, 100)
    samples_per_leg = as_count(samples_per_leg, "samples_per_leg", 1, 1000)
    tol = as_tolerance(tol, "tol")
    max_iter = as_count(max_iter, "max_iter", 1, 1000)
    eo = ephemeris_orbit
    for name in ("epochs_tdb", "states_km", "orbit", "nodes_per_rev", "ephemeris"):
        if not hasattr(eo, name):
            raise ValueError(f"invalid argument `ephemeris_orbit`: must be a librate.EphemerisOrbit (no `{name}`)")
    if abs(eo.orbit.period - solution.orbit.period) > 1e-9 * solution.orbit.period:
        raise ValueError(f"invalid argument `ephemeris_orbit`: its orbit's period {eo.orbit.period} differs from the solution's "
                         f"{solution.orbit.period}")
    srp = isinstance(use_body, FacetBody)
    facets = [(f.area, tuple(f.normal), tuple(f.center), f.ca, f.cs, f.cd) for f in use_body.facets] if srp else None
    eph = eo.ephemeris if eo.ephemeris is not None else Ephemeris()
    model = _core.EphemerisAttitudeModel(eph._core, tuple(float(v) for v in use_body.moments), gg, facets, eclipses=bool(eclipses))

    epochs, taus, orbits = _node_times(eo, nodes_per_leg)
    q_ref, w_ref = _reference_at(solution, ref_body, q0, w0, k_periods, taus)
    q_g, w_g = model.place(epochs, q_ref, w_ref)
    if correct:
        out = model.correct(epochs, orbits, q_g, w_g, tol=tol, max_iter=max_iter, tolerances=(float(rtol), float(atol)))
        if not out["converged"]:
            d = np.asarray(out["defects"])
            raise ConvergenceError(f"attitude_to_ephemeris: the multiple-shooting corrector stopped ({out['reason']}) after "
                                   f"{out['iterations']} iterations; largest defect {np.max(np.abs(d[:, :3])):.3e} rad, tolerance {tol}")
    else:
        out = model.legs(epochs, orbits, q_g, w_g, rtol=float(rtol), atol=float(atol))
    q, w, d = np.asarray(out["q"]), np.asarray(out["w"]), np.asarray(out["defects"])
    defect_rad = np.linalg.norm(d[:, :3], axis=1)
    defect_rate = np.linalg.norm(d[:, 3:], axis=1) / np.linalg.norm(w[1:], axis=1)

    # deviation figures at the sample epochs
    t_s = _samples(epochs, samples_per_leg)
    tau_s = np.interp(t_s, epochs, taus)
    q_rs, w_rs = _reference_at(solution, ref_body, q0, w0, k_periods, tau_s)
    leg = np.minimum(np.searchsorted(epochs, t_s, side="right") - 1, epochs.size - 2)
    qs = np.empty((t_s.size, 4))
    ws = np.empty((t_s.size, 3))
    for i in range(epochs.size - 1):
        sel = np.flatnonzero(leg == i)
        y0 = np.concatenate([orbits[i], q[i], w[i]])
        _, ys, _ = model.propagate(y0, epochs[i], epochs[i + 1] - epochs[i],
                                   t_eval=np.ascontiguousarray(t_s[sel] - epochs[i]), rtol=rtol, atol=atol)
        qs[sel], ws[sel] = ys[:, 6:10], ys[:, 10:]
    err, rate, q_rot = _deviation(model, t_s, qs, ws, q_rs, w_rs)
    y0 = np.concatenate([orbits[0], q_g[0], w_g[0]])
    _, yp, _ = model.propagate(y0, epochs[0], epochs[-1] - epochs[0], t_eval=np.ascontiguousarray(t_s - epochs[0]), rtol=rtol, atol=atol)
    perr, prate, _ = _deviation(model, t_s, yp[:, 6:10], yp[:, 10:], q_rs, w_rs)
    revolution = np.minimum(np.floor(tau_s / eo.orbit.period + 1e-9), max(eo.revolutions - 1, 0)).astype(int)
    return EphemerisAttitude(solution=solution, ephemeris_orbit=eo, body=use_body, epochs_tdb=epochs, q=q, w=w, orbit_states_km=orbits,
                             corrected=bool(correct), iterations=int(out["iterations"]), reason=str(out["reason"]), defect_rad=defect_rad,
                             defect_rate=defect_rate, monodromy=np.asarray(out["monodromy"]), t_tdb=t_s, revolution=revolution,
                             pointing_error_deg=err, rate_error=rate, placed_pointing_error_deg=perr, placed_rate_error=prate,
                             gravity_gradient=gg, srp=srp, q_rotating=q_rot, q_rotating_cr3bp=np.asarray(q_rs))
