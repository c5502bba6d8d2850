"""Rigid-body attitude coupled with the CR3BP orbit (thesis ch. 3.1-3.2, docs/physics.md, attitude).

The 3-D model integrates the orbit (6), the quaternion q of the body relative to the synodic
frame (scalar last) and the inertial angular velocity w in body axes; the planar reduced model
integrates (phi, wz), phi the angle from the synodic X axis to the body x axis and wz the
inertial rate, along the orbit. Torques: gravity gradient of both primaries (switchable per
primary). All quantities nondimensional (rates in 1/TU).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .. import _core
from .._checks import as_float_array, as_state, as_time_span
from ..orbits.propagation import Stats, integration_options
from ..orbits.system import System, resolve_system
from .body import EULER_SEQUENCES, RigidBody, torque_names
from .flexible import FlexibleBody, FlexibleResponse, enabled_primaries, flexible_attitude, initial_deflection
from .srp import FacetBody, FlatPlate, Sun

#: The core's orbit modes by the names of ``propagate_attitude(orbit=...)``.
_ORBIT_MODES = {"integrate": _core.OrbitMode.INTEGRATE, "held": _core.OrbitMode.HELD, "coupled": _core.OrbitMode.COUPLED}

__all__ = ["AttitudeTrajectory", "propagate_attitude"]


@dataclass(frozen=True)
class AttitudeTrajectory:
    """The result of `propagate_attitude`.

    Attributes
    ----------
    system : System
        The system.
    body : RigidBody
        The body.
    torque_models : tuple of str
        The torques integrated.
    planar : bool
        The reduced planar model was integrated.
    t : numpy.ndarray, shape (n,)
        Times (TU).
    orbit : numpy.ndarray, shape (n, 6)
        The orbit states.
    q : numpy.ndarray, shape (n, 4)
        Scalar-last quaternions of the body relative to the synodic frame.
    w : numpy.ndarray, shape (n, 3)
        Inertial angular velocity in body axes (1/TU).
    phi, wz : numpy.ndarray, shape (n,) or None
        Planar runs: the angle of the body x axis from the synodic X axis (rad) and the inertial
        rate (1/TU).
    stm : numpy.ndarray or None
        When asked: 13x13 (3-D) or 2x2 (planar, d(phi, wz)) at the final time.
    stats : Stats
        Step statistics.
    flex : FlexibleResponse or None
        For a `FlexibleBody`: the deflections ``flex.q`` (n, appendages; m) and their rates
        ``flex.qdot`` (m/TU).
    """

    system: System
    body: RigidBody
    torque_models: tuple[str, ...]
    planar: bool
    t: np.ndarray
    orbit: np.ndarray
    q: np.ndarray
    w: np.ndarray
    phi: np.ndarray | None
    wz: np.ndarray | None
    stm: np.ndarray | None
    stats: Stats
    flex: FlexibleResponse | None = None

    def dcm(self) -> np.ndarray:
        """(n, 3, 3) attitude matrices A (synodic -> body components)."""
        from scipy.spatial.transform import Rotation

        return np.transpose(Rotation.from_quat(self.q).as_matrix(), (0, 2, 1))

    def euler_angles(self, sequence: str = "123") -> np.ndarray:
        """(n, 3) Euler angles of the body relative to the synodic frame (rad)."""
        from scipy.spatial.transform import Rotation

        return Rotation.from_quat(self.q).as_euler(EULER_SEQUENCES.get(sequence, sequence))

    def local_vertical_frame(self, primary: str | int = "earth") -> np.ndarray:
        """(n, 3, 3) matrices whose columns are the local-vertical axes of ``primary`` in synodic
        components: x radial (from the primary), z along the orbit normal about that primary
        (inertial velocity), y completing the triad."""
        k = {"earth": 0, "moon": 1, 1: 0, 2: 1}.get(primary)
        if k is None:
            raise ValueError(f"invalid argument `primary`: must be 'earth', 'moon', 1 or 2, got {primary!r}")
        r = self.orbit[:, :3] - self.system.primary_positions()[k]
        v = self.orbit[:, 3:] + np.cross([0.0, 0.0, 1.0], r)
        x = r / np.linalg.norm(r, axis=1, keepdims=True)
        z = np.cross(r, v)
        z /= np.linalg.norm(z, axis=1, keepdims=True)
        y = np.cross(z, x)
        return np.stack([x, y, z], axis=2)

    def relative_to_vertical(self, primary: str | int = "earth", sequence: str = "123") -> np.ndarray:
        """(n, 3) Euler angles of the body relative to the local vertical of a primary (roll,
        pitch, yaw about the radial, along-track and normal axes for "123")."""
        from scipy.spatial.transform import Rotation

        a_bl = self.dcm() @ self.local_vertical_frame(primary)
        return Rotation.from_matrix(np.transpose(a_bl, (0, 2, 1))).as_euler(EULER_SEQUENCES.get(sequence, sequence))

    def torques(self) -> np.ndarray:
        """(n, 3) gravity-gradient torque of the run in body axes (inertia units / TU^2)."""
        if self.flex is not None:  # flexible runs: the tidal torque on the deformed body, kg m^2 / TU^2
            return np.stack([np.zeros_like(self.t), np.zeros_like(self.t), self.flex.energies()["torque"] * self.system.tu_s**2], axis=1)
        states = np.ascontiguousarray(np.hstack([self.orbit, self.q, self.w]))
        names = [n for n in self.torque_models if n != "srp"]
        return _core.attitude_torques(self.system.mu, list(self.body.moments), names, np.ascontiguousarray(self.t), states)


def propagate_attitude(
    system: System | str,
    orbit_state,
    attitude,
    body: RigidBody,
    t_span,
    *,
    torques: Sequence[str] = ("gravity_gradient",),
    planar: bool = False,
    orbit: str = "integrate",
    srp=None,
    sun=None,
    srp_force: bool = False,
    stm: bool = False,
    t_eval=None,
    rtol: float = 1e-12,
    atol: float = 1e-12,
    h0: float | None = None,
    h_min: float = 0.0,
    h_max: float = math.inf,
    max_steps: int = 1_000_000,
    safety: float = 0.8,
    fixed_step: float | None = None,
    deflection=None,
) -> AttitudeTrajectory:
    """Propagate the attitude of a rigid body along its CR3BP orbit.

    Parameters
    ----------
    system : System or str
        The system, or a preset name.
    orbit_state : array_like, shape (6,)
        The initial orbit state (nondimensional).
    attitude : (q, w) or (phi0, wz0)
        3-D: q the scalar-last unit quaternion of the body relative to the synodic frame and w
        the inertial angular velocity in body axes (1/TU); ``planar`` (or a `FlexibleBody`): the
        angle phi0 (rad) and the inertial rate wz0 (1/TU; phidot = wz - 1).
    body : RigidBody, FacetBody or FlexibleBody
        The body; a `FlexibleBody` runs the planar flexible model.
    t_span : float or (float, float)
        Final time tf, or (t0, tf), in TU.
    torques : sequence of str, default ("gravity_gradient",)
        Torque names (``librate.attitude.TORQUES``); "gravity_gradient_earth" alone is the
        two-body limit; "srp" with a `FacetBody` (3-D).
    planar : bool, default False
        The reduced planar model.
    orbit : {"integrate", "held", "coupled"}
        "integrate": the point-mass CR3BP; "held": the body kept at its initial position (as at
        the Lagrange points); "coupled": with the second-order extended-body acceleration (thesis
        eq. 37; needs ``body.mass_kg``, inertia in kg m^2).
    srp : FlatPlate, optional
        Planar runs: the simplified SRP plate.
    sun : Sun, optional
        3-D SRP: the Sun (default phase 0).
    srp_force : bool, default False
        3-D SRP: also apply the SRP force to the orbit (needs ``body.mass_kg``).
    stm : bool, default False
        Also integrate the variational equations (13x13 in 3-D, 2x2 planar).
    t_eval : array_like, optional
        Output times instead of every accepted step.
    rtol, atol : float, default 1e-12
        Error tolerances.
    h0, h_min, h_max, max_steps, safety, fixed_step
        Step control, as in `propagate`.
    deflection : None, "quasi-static" or (q0, qdot0)
        A `FlexibleBody`'s initial deflections: undeformed at rest, the closed-form quasi-static
        ones, or given (m, m/TU).

    Returns
    -------
    AttitudeTrajectory
        Times, orbit, quaternions, rates (and phi, wz when planar; the STM when asked).

    Raises
    ------
    ValueError
        A bad argument, naming it and the allowed values.
    IntegrationError
        The integration cannot reach tf.

    Notes
    -----
    Both SRP models are integrated piecewise between the faces' Sun-terminator crossings (the
    plate law is only C1 there).

    Examples
    --------
    >>> import librate
    >>> dro = librate.dro(period_days=12.66)
    >>> body = librate.RigidBody.from_kz(0.8)
    >>> tr = librate.propagate_attitude("earth-moon", dro.state0, (0.0, 1.0), body, dro.period, planar=True)
    >>> tr.phi.shape == tr.t.shape
    True
    """
    sys_ = resolve_system(system)
    s = as_state(orbit_state, "orbit_state")
    t0, tf = as_time_span(t_span)
    if not isinstance(body, (RigidBody, FlexibleBody)):
        raise ValueError(f"invalid argument `body`: must be a librate.RigidBody or librate.FlexibleBody, got {body!r}")
    names = torque_names(torques)
    if srp is not None and not (planar and isinstance(srp, FlatPlate)):
        raise ValueError("invalid argument `srp`: a librate.FlatPlate, for planar runs (3-D runs use a FacetBody with "
                         "torques including 'srp')")
    if planar and "srp" in names:
        raise ValueError("invalid argument `torques`: planar runs take the SRP plate through srp=FlatPlate(...)")
    if not planar and ("srp" in names or srp_force) and not isinstance(body, FacetBody):
        raise ValueError("invalid argument `body`: the SRP torque or force needs a librate.FacetBody")
    if sun is not None and not isinstance(sun, Sun):
        raise ValueError(f"invalid argument `sun`: must be a librate.Sun, got {sun!r}")
    if not isinstance(srp_force, (bool, np.bool_)):
        raise ValueError(f"invalid argument `srp_force`: must be True or False, got {srp_force!r}")
    # keywords that would be silently ignored are refused by name (issue 12)
    if planar and srp_force:
        raise ValueError("invalid argument `srp_force`: planar runs have no SRP force on the orbit (3-D runs with a FacetBody do)")
    if sun is not None and (planar or isinstance(body, FlexibleBody)):
        raise ValueError("invalid argument `sun`: planar runs take the Sun from the plate, srp=FlatPlate(..., sun=Sun(...))")
    if sun is not None and not isinstance(body, FacetBody):
        raise ValueError("invalid argument `sun`: only a librate.FacetBody feels the Sun (solar radiation pressure); a "
                         "plain RigidBody does not")
    if orbit not in ("integrate", "held", "coupled"):
        raise ValueError(f"invalid argument `orbit`: must be 'integrate', 'held' or 'coupled', got {orbit!r}")
    opts = integration_options(rtol, atol, h0, h_min, h_max, max_steps, safety, fixed_step)
    te = None if t_eval is None else np.ascontiguousarray(as_float_array(t_eval, "t_eval"), dtype=np.float64).ravel()
    if isinstance(body, FlexibleBody):
        if srp is not None or "srp" in names or srp_force:
            raise ValueError("invalid argument `srp`: the flexible model has no solar radiation pressure yet; use a RigidBody or FacetBody")
        return _propagate_flexible(sys_, s, attitude, body, t0, tf, names, orbit, opts, te, deflection, stm)
    if deflection is not None:
        raise ValueError("invalid argument `deflection`: only a librate.FlexibleBody has deflections")

    if planar:
        if orbit == "coupled":
            raise ValueError("invalid argument `orbit`: the planar reduced model has no orbital coupling; use planar=False")
        phi0, wz0 = _pair(attitude)
        primaries = [any(n in ("gravity_gradient", "gravity_gradient_earth") for n in names),
                     any(n in ("gravity_gradient", "gravity_gradient_moon") for n in names)]
        model = _core.PlanarModel(sys_.mu, body.kz, primaries=primaries, held=orbit == "held", plate=None if srp is None else srp._plate())
        r = _core.planar_propagate(model, [float(v) for v in s], (phi0, wz0), (t0, tf), options=opts, stm=bool(stm), t_eval=te)
        phi, wz = r.phi, r.wz
        zero = np.zeros_like(phi)
        q = np.stack([zero, zero, np.sin(0.5 * phi), np.cos(0.5 * phi)], axis=1)
        w = np.stack([zero, zero, wz], axis=1)
        return AttitudeTrajectory(sys_, body, names, True, r.t, r.orbit, q, w, phi, wz, r.stm, Stats.from_core(r.stats))

    if isinstance(body, RigidBody) and body.is_rod:
        raise ValueError(f"invalid argument `body`: a body with a zero principal moment (Kz = {body.kz:g}, a thin rod) has no 3-D attitude "
                         "dynamics; use planar=True (the planar model depends only on Kz)")
    q0, w0 = _quaternion_and_rate(attitude)
    inertia_nd = None
    if orbit == "coupled":
        if body.mass_kg is None:
            raise ValueError("invalid argument `body`: orbit='coupled' needs body.mass_kg (kg) and the inertia in kg m^2")
        lu_m = sys_.lu_km * 1e3
        inertia_nd = [m / (body.mass_kg * lu_m * lu_m) for m in body.moments]
    state0 = [*map(float, s), *map(float, q0), *map(float, w0)]
    srp_model = None
    if isinstance(body, FacetBody):
        sun = sun or Sun()
        force = None
        if srp_force:
            if body.mass_kg is None:
                raise ValueError("invalid argument `body`: srp_force needs body.mass_kg")
            force = (float(body.mass_kg), sys_.lu_km * 1e3)
        srp_model = _core.SrpModel([f._tuple() for f in body.facets], sun=(float(sun.theta0), float(sun.omega), float(sun.pressure)),
                                   tu_s=float(sys_.tu_s), force=force)
    model = _core.AttitudeModel(sys_.mu, list(body.moments), list(names), orbit=_ORBIT_MODES[orbit], inertia_nd=inertia_nd, srp=srp_model)
    r = _core.attitude_propagate(model, state0, (t0, tf), options=opts, stm=bool(stm), t_eval=te)
    st = r.states
    return AttitudeTrajectory(sys_, body, names, False, r.t, st[:, :6], st[:, 6:10], st[:, 10:], None, None, r.stm,
                              Stats.from_core(r.stats))


def _pair(attitude) -> tuple[float, float]:
    try:
        phi0, wz0 = (float(v) for v in attitude)
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `attitude`: planar runs take (phi0, wz0), got {attitude!r}") from None
    if not (math.isfinite(phi0) and math.isfinite(wz0)):
        raise ValueError(f"invalid argument `attitude`: (phi0, wz0) must be finite, got {attitude!r}")
    return phi0, wz0


def _quaternion_and_rate(attitude) -> tuple[np.ndarray, np.ndarray]:
    try:
        q, w = attitude
        q = np.asarray(q, dtype=np.float64).ravel()
        w = np.asarray(w, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise ValueError("invalid argument `attitude`: 3-D runs take (q, w), q of 4 (scalar last) and w of 3 "
                         f"components, got {attitude!r}") from None
    if q.shape != (4,) or w.shape != (3,) or not (np.all(np.isfinite(q)) and np.all(np.isfinite(w))):
        raise ValueError("invalid argument `attitude`: q must have 4 finite components (scalar last) and w 3, got shapes "
                         f"{q.shape}, {w.shape}")
    n = np.linalg.norm(q)
    if abs(n - 1) > 1e-6:
        raise ValueError(f"invalid argument `attitude`: q must be a unit quaternion, |q| = {n}")
    return q / n, w


def _propagate_flexible(sys_, s, attitude, body, t0, tf, names, orbit, opts, te, deflection, stm) -> AttitudeTrajectory:
    """The branch of :func:`librate.propagate_attitude` for a :class:`FlexibleBody`."""
    if stm:
        raise ValueError("invalid argument `stm`: the flexible model has no STM; use stm=False")
    if orbit not in ("integrate", "held"):
        raise ValueError(f"invalid argument `orbit`: the flexible model takes 'integrate' or 'held', got {orbit!r}")
    phi0, wz0 = flexible_attitude(attitude)
    primaries = enabled_primaries(names)
    held = orbit == "held"
    q0, qd0 = initial_deflection(deflection, sys_, body, primaries, held, s, phi0, wz0)
    r = _core.flexible_propagate(body._core_model(sys_, primaries, held), [float(v) for v in s], (phi0, wz0), list(q0), list(qd0),
                                 (t0, tf), options=opts, t_eval=te)
    phi, wz = r.phi, r.wz
    zero = np.zeros_like(phi)
    quat = np.stack([zero, zero, np.sin(0.5 * phi), np.cos(0.5 * phi)], axis=1)
    w = np.stack([zero, zero, wz], axis=1)
    flex = FlexibleResponse(sys_, body, tuple(primaries), r.t, r.orbit, phi, wz, r.q, r.qdot)
    return AttitudeTrajectory(sys_, body, tuple(names), True, r.t, r.orbit, quat, w, phi, wz, None, Stats.from_core(r.stats), flex=flex)
