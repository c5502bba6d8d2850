"""Earth-centred inertial (ECI) frame and osculating Keplerian elements about the Earth.

The synodic frame turns at rate 1 about +z relative to inertial axes. With the ECI axes
aligned with the synodic ones at t = 0 up to the angle ``theta0``, at time t the synodic axes
are rotated by theta(t) = theta0 + t, and a synodic state (r, v) (nondimensional, Earth at
(-mu, 0, 0)) is, relative to the Earth in the ECI frame,

    r_I = R(theta) (r + (mu, 0, 0)),
    v_I = R(theta) (v + z_hat x (r + (mu, 0, 0))),

R(theta) the rotation by theta about z. The Earth itself moves on a circle of radius mu about the
barycentre, so "inertial" here means non-rotating and Earth-centred (as the thesis uses it).
Outputs carry km and km/s through the system's ``lu_km``, ``vu_km_s``.

The osculating ellipse is the Keplerian orbit about the Earth alone (the Moon neglected) with
the same ECI position and velocity (thesis Sec. 2.2.4): gravitational parameter 1 - mu in
nondimensional units, GM_earth = (1 - mu) lu_km^3 / tu_s^2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._checks import as_state
from .propagation import propagate
from .system import System, resolve_system

__all__ = ["synodic_to_eci", "eci_to_synodic", "OsculatingElements", "osculating_elements", "MeanElements", "mean_elements"]

_Z = np.array([0.0, 0.0, 1.0])
# Below this |sin i| an orbit counts as planar (in the xy plane): the node is undefined.
_PLANAR_SIN_I = 1e-10


def _times_states(t, states, name: str = "states") -> tuple[np.ndarray, np.ndarray, bool]:
    """Broadcast t (scalar or (n,)) against states ((6,) or (n, 6)); the flag says 'single state'."""
    arr = np.asarray(states, dtype=np.float64)
    single = arr.ndim == 1
    if single:
        arr = arr.reshape(1, -1)
    if arr.ndim != 2 or arr.shape[1] != 6:
        raise ValueError(f"invalid argument `{name}`: must have shape (6,) or (n, 6), got shape {np.shape(states)}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"invalid argument `{name}`: must be finite")
    ta = np.asarray(t, dtype=np.float64)
    if ta.ndim == 0:
        ta = np.full(arr.shape[0], float(ta))
    elif ta.ndim == 1 and ta.shape[0] == arr.shape[0]:
        pass
    elif single and ta.ndim == 1:
        # One state, many times is ambiguous: refuse rather than guess.
        raise ValueError(f"invalid argument `t`: one state needs one time, got {ta.shape[0]} times")
    else:
        raise ValueError(f"invalid argument `t`: must be a number or one time per state ({arr.shape[0]}), got shape {ta.shape}")
    if not np.all(np.isfinite(ta)):
        raise ValueError("invalid argument `t`: times must be finite")
    return ta, arr, single


def _check_angle(theta0) -> float:
    if not (isinstance(theta0, (int, float, np.floating)) and math.isfinite(theta0)):
        raise ValueError(f"invalid argument `theta0`: must be a finite angle (rad), got {theta0!r}")
    return float(theta0)


def _rotate(theta: np.ndarray, v: np.ndarray, sign: float = 1.0) -> np.ndarray:
    """Rotate rows of v (n, 3) by sign * theta about z."""
    c, s = np.cos(theta), sign * np.sin(theta)
    out = np.empty_like(v)
    out[:, 0] = c * v[:, 0] - s * v[:, 1]
    out[:, 1] = s * v[:, 0] + c * v[:, 1]
    out[:, 2] = v[:, 2]
    return out


def _eci_nondim(mu: float, t: np.ndarray, s: np.ndarray, theta0: float) -> tuple[np.ndarray, np.ndarray]:
    """Earth-relative ECI position and velocity in nondimensional units."""
    r_e = s[:, :3] + np.array([mu, 0.0, 0.0])
    v_e = s[:, 3:] + np.cross(_Z, r_e)
    theta = theta0 + t
    return _rotate(theta, r_e), _rotate(theta, v_e)


def synodic_to_eci(system: System | str, t, states, theta0: float = 0.0) -> np.ndarray:
    """Synodic states to Earth-centred inertial states in km and km/s.

    Parameters
    ----------
    system : System or str
        The system.
    t : float or array_like
        Time(s) (TU).
    states : array_like, shape (6,) or (n, 6)
        Synodic nondimensional states.
    theta0 : float, default 0.0
        The angle of the synodic x axis from the ECI X axis at t = 0 (rad).

    Returns
    -------
    numpy.ndarray
        ECI states (km, km/s), the shape of ``states``.

    See Also
    --------
    - [`eci_to_synodic`][librate.orbits.frames.eci_to_synodic]: the inverse.
    """
    sys_ = resolve_system(system)
    ta, s, single = _times_states(t, states)
    r, v = _eci_nondim(sys_.mu, ta, s, _check_angle(theta0))
    out = np.hstack([r * sys_.lu_km, v * sys_.vu_km_s])
    return out[0] if single else out


def eci_to_synodic(system: System | str, t, states_km, theta0: float = 0.0) -> np.ndarray:
    """Earth-centred inertial states (km, km/s) to synodic nondimensional states: the inverse of
    `synodic_to_eci`.

    Parameters
    ----------
    system : System or str
        The system.
    t : float or array_like
        Time(s) (TU).
    states_km : array_like, shape (6,) or (n, 6)
        ECI states (km, km/s).
    theta0 : float, default 0.0
        The angle of the synodic x axis from the ECI X axis at t = 0 (rad).

    Returns
    -------
    numpy.ndarray
        Synodic states, the shape of ``states_km``.
    """
    sys_ = resolve_system(system)
    ta, s, single = _times_states(t, states_km, "states_km")
    theta = _check_angle(theta0) + ta
    r_e = _rotate(theta, s[:, :3] / sys_.lu_km, -1.0)
    v_e = _rotate(theta, s[:, 3:] / sys_.vu_km_s, -1.0)
    out = np.hstack([r_e - np.array([sys_.mu, 0.0, 0.0]), v_e - np.cross(_Z, r_e)])
    return out[0] if single else out


@dataclass(frozen=True)
class OsculatingElements:
    """Osculating Keplerian elements about the Earth, one entry per time.

    ``a_km`` semi-major axis (negative for hyperbolic states), ``e`` eccentricity, ``i``
    inclination in [0, pi], ``raan`` right ascension of the ascending node, ``argp`` argument of
    perigee and ``true_anomaly``, all angles in radians in (-pi, pi] except ``i``. For a planar
    orbit (|sin i| < 1e-10) the node is undefined: ``raan`` is 0 and ``argp`` is the angle of the
    eccentricity vector in the inertial XY plane measured from X counterclockwise about +Z (the
    longitude of perigee), whether the motion is prograde or retrograde. ``true_anomaly`` runs
    from the eccentricity vector to the position in the direction of motion. For e -> 0 the
    perigee, hence ``argp`` and ``true_anomaly``, is undefined (their sum stays meaningful).
    """

    t: np.ndarray
    a_km: np.ndarray
    e: np.ndarray
    i: np.ndarray
    raan: np.ndarray
    argp: np.ndarray
    true_anomaly: np.ndarray


def _elements(gm: float, r: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, ...]:
    rn = np.linalg.norm(r, axis=1)
    v2 = np.einsum("ij,ij->i", v, v)
    rv = np.einsum("ij,ij->i", r, v)
    h = np.cross(r, v)
    hn = np.linalg.norm(h, axis=1)
    evec = ((v2 - gm / rn)[:, None] * r - rv[:, None] * v) / gm
    e = np.linalg.norm(evec, axis=1)
    a = 1.0 / (2.0 / rn - v2 / gm)
    hhat = h / hn[:, None]
    inc = np.arccos(np.clip(hhat[:, 2], -1.0, 1.0))
    node = np.cross(_Z, h)
    planar = np.hypot(hhat[:, 0], hhat[:, 1]) < _PLANAR_SIN_I
    raan = np.where(planar, 0.0, np.arctan2(node[:, 1], node[:, 0]))
    nhat = np.where(planar[:, None], np.array([1.0, 0.0, 0.0]), node / np.maximum(np.linalg.norm(node, axis=1), 1e-300)[:, None])
    argp_3d = np.arctan2(np.einsum("ij,ij->i", np.cross(nhat, evec), hhat), np.einsum("ij,ij->i", nhat, evec))
    argp = np.where(planar, np.arctan2(evec[:, 1], evec[:, 0]), argp_3d)
    nu = np.arctan2(np.einsum("ij,ij->i", np.cross(evec, r), hhat), np.einsum("ij,ij->i", evec, r))
    return a, e, inc, raan, argp, nu


def osculating_elements(system: System | str, t, states, theta0: float = 0.0) -> OsculatingElements:
    """Osculating Keplerian elements about the Earth of synodic states.

    The states go to the ECI frame (`synodic_to_eci` with ``theta0``); GM = 1 - mu in
    nondimensional units.

    Parameters
    ----------
    system : System or str
        The system.
    t : float or array_like
        Time(s) (TU).
    states : array_like, shape (6,) or (n, 6)
        Synodic nondimensional states.
    theta0 : float, default 0.0
        The synodic x axis's ECI angle at t = 0 (rad).

    Returns
    -------
    OsculatingElements
        Arrays of length n (a, e, i, the node, the argument of perigee, the anomaly).
    """
    sys_ = resolve_system(system)
    ta, s, _ = _times_states(t, states)
    r, v = _eci_nondim(sys_.mu, ta, s, _check_angle(theta0))
    a, e, inc, raan, argp, nu = _elements(1.0 - sys_.mu, r, v)
    return OsculatingElements(t=ta, a_km=a * sys_.lu_km, e=e, i=inc, raan=raan, argp=argp, true_anomaly=nu)


@dataclass(frozen=True)
class MeanElements:
    """Time averages of the osculating elements over each of ``n_periods`` periods of an orbit.

    ``a_km`` and ``e`` are the averages over all samples (the orbit is periodic, so every period
    gives the same up to integration error; the per-period values are in ``a_km_per_period``,
    ``e_per_period``). ``argp_per_period`` is the mean (continuously unwrapped) argument of
    perigee over each period; ``argp_drift_per_period`` its change from one period to the next
    (rad), and ``argp_drift`` the slope of a least-squares line through ``argp_per_period``
    (rad per period), the secular apsidal drift. ``elements`` holds every sample.
    """

    period: float
    a_km: float
    e: float
    argp_drift: float
    a_km_per_period: np.ndarray
    e_per_period: np.ndarray
    argp_per_period: np.ndarray
    argp_drift_per_period: np.ndarray
    elements: OsculatingElements

    @property
    def argp_rate(self) -> float:
        """Secular apsidal drift per unit time (rad/TU)."""
        return self.argp_drift / self.period


def mean_elements(
    system: System | str,
    orbit_state0,
    period: float,
    *,
    n_periods: int = 3,
    samples_per_period: int = 2000,
    theta0: float = 0.0,
    rtol: float = 1e-13,
    atol: float = 1e-13,
) -> MeanElements:
    """Mean osculating elements about the Earth along a periodic orbit, and its apsidal drift
    (thesis Table 1).

    The synodic orbit is propagated over ``n_periods`` periods and sampled at
    ``samples_per_period`` uniform times per period; the osculating a, e and argument of perigee
    are averaged over each period. A synodic orbit of period T returns rotated by T in the ECI
    frame, so its drift per period is T - 2 pi modulo 2 pi; the 1:1 resonant DRO (T = 2 pi) has
    none.

    Parameters
    ----------
    system : System or str
        The system.
    orbit_state0 : array_like, shape (6,)
        The orbit's initial state.
    period : float
        Its period (TU).
    n_periods : int, default 3
        Periods averaged.
    samples_per_period : int, default 2000
        Samples per period.
    theta0 : float, default 0.0
        The synodic x axis's ECI angle at t = 0 (rad).
    rtol, atol : float, default 1e-13
        Integration tolerances.

    Returns
    -------
    MeanElements
        The per-period means and the apsidal drift.
    """
    sys_ = resolve_system(system)
    s0 = as_state(orbit_state0, "orbit_state0")
    if not (isinstance(period, (int, float, np.floating)) and math.isfinite(period) and period > 0):
        raise ValueError(f"invalid argument `period`: must be a finite number > 0 (TU), got {period!r}")
    if not isinstance(n_periods, (int, np.integer)) or isinstance(n_periods, bool) or n_periods < 1:
        raise ValueError(f"invalid argument `n_periods`: must be an integer >= 1, got {n_periods!r}")
    if not isinstance(samples_per_period, (int, np.integer)) or isinstance(samples_per_period, bool) or samples_per_period < 8:
        raise ValueError(f"invalid argument `samples_per_period`: must be an integer >= 8, got {samples_per_period!r}")
    m, k = int(samples_per_period), int(n_periods)
    t = np.arange(m * k) * (float(period) / m)
    tr = propagate(sys_, s0, float(period) * k, t_eval=t, rtol=rtol, atol=atol, collision="point")
    el = osculating_elements(sys_, tr.t, tr.y, theta0=theta0)
    argp = np.unwrap(el.argp)
    a_pp = el.a_km.reshape(k, m).mean(axis=1)
    e_pp = el.e.reshape(k, m).mean(axis=1)
    w_pp = argp.reshape(k, m).mean(axis=1)
    drift = float(np.polyfit(np.arange(k), w_pp, 1)[0]) if k >= 2 else math.nan
    return MeanElements(
        period=float(period),
        a_km=float(el.a_km.mean()),
        e=float(el.e.mean()),
        argp_drift=drift,
        a_km_per_period=a_pp,
        e_per_period=e_pp,
        argp_per_period=w_pp,
        argp_drift_per_period=np.diff(w_pp),
        elements=el,
    )
