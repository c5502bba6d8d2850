"""Equilibrium attitudes of a rigid body held at a collinear Lagrange point (Kane & Marsh 1971,
Robinson 1974; the derivation is in docs/physics/attitude-equilibria.md).

A body kept at L1, L2 or L3 with its principal axes on the synodic axes, turning with the
synodic frame (inertial rate w = e_Z), is in equilibrium: the tidal tensor of the two primaries
is diagonal there. Linearised about it, the attitude (a small rotation theta in body axes and the
rate change dw) obeys d(theta, dw)/dt = M (theta, dw). The rotation about the synodic Z axis (the
thesis's yaw, the classical pitch) decouples; the rotations about X and Y (the radial and
along-track axes) are coupled by the frame rotation. With sigma = (1 - mu)/r1^3 + mu/r2^3 at the
point (the thesis's h = 3 sigma) and the inertia ratios of the moments A, B, C about the synodic
X, Y, Z axes,

    K1 = (C - B) / A,   K2 = (C - A) / B,   K3 = (B - A) / C,

the characteristic polynomial factors as

    (s^2 + 3 sigma K3) (s^4 + (1 + 3 sigma K2 + K1 K2) s^2 + (1 + 3 sigma) K1 K2),

and the equilibrium is linearly stable (every eigenvalue imaginary and the roll-yaw pair
distinct) when K3 > 0, K1 K2 > 0, 1 + 3 sigma K2 + K1 K2 > 0 and
(1 + 3 sigma K2 + K1 K2)^2 > 4 (1 + 3 sigma) K1 K2. With sigma = 1 these are the classical
conditions of a satellite on a circular orbit (DeBra-Delp).

:func:`attitude_equilibrium` linearises the Rust 3-D model (exact Jacobian by dual numbers);
:func:`closed_form_eigenvalues` evaluates the polynomial above; :func:`equilibrium_stability`
tabulates the stability over the plane of Robinson's two inertia ratios (thesis Fig. 19).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import _core
from .._checks import as_count
from ..orbits.system import System, resolve_system
from .body import RigidBody

__all__ = ["AttitudeEquilibrium", "attitude_equilibrium", "closed_form_eigenvalues", "characteristic_polynomial", "inertia_ratios",
           "moments_from_ratios", "equilibrium_stability", "STABILITY_TOL", "ROLL_YAW_REGIONS"]

#: An eigenvalue counts as imaginary when |Re s| <= STABILITY_TOL * max(1, |s|).
STABILITY_TOL = 1e-9
#: Codes of the roll-yaw pair in :func:`equilibrium_stability`.
ROLL_YAW_REGIONS = {0: "stable", 1: "divergent (a real pair)", 2: "flutter (a complex quadruple)"}


def _point(point) -> int:
    if isinstance(point, bool) or point not in (1, 2, 3, "L1", "L2", "L3"):
        raise ValueError(f"invalid argument `point`: must be 1, 2, 3 (or 'L1', 'L2', 'L3'), the collinear points; got {point!r}")
    return int(point[1]) if isinstance(point, str) else int(point)


def inertia_ratios(moments) -> tuple[float, float, float]:
    """(K1, K2, K3) = ((C - B)/A, (C - A)/B, (B - A)/C) of the moments (A, B, C) about the
    synodic X, Y, Z axes."""
    a, b, c = (float(v) for v in moments)
    return (c - b) / a, (c - a) / b, (b - a) / c


def characteristic_polynomial(sigma: float, moments) -> tuple[np.ndarray, np.ndarray]:
    """The closed-form factors of the linearised attitude's characteristic polynomial in s
    (coefficients, highest power first): the pitch factor s^2 + 3 sigma K3 and the roll-yaw
    factor s^4 + (1 + 3 sigma K2 + K1 K2) s^2 + (1 + 3 sigma) K1 K2."""
    k1, k2, k3 = inertia_ratios(moments)
    return (np.array([1.0, 0.0, 3 * sigma * k3]),
            np.array([1.0, 0.0, 1 + 3 * sigma * k2 + k1 * k2, 0.0, (1 + 3 * sigma) * k1 * k2]))


def closed_form_eigenvalues(sigma: float, moments) -> np.ndarray:
    """The six roots of :func:`characteristic_polynomial`, in closed form (quadratics in s^2):
    the pitch pair, then the two roll-yaw pairs, each as (+s, -s)."""
    k1, k2, k3 = inertia_ratios(moments)
    b = 1 + 3 * sigma * k2 + k1 * k2
    c = (1 + 3 * sigma) * k1 * k2
    d = np.sqrt(complex(b * b - 4 * c))
    out = []
    for x in (complex(-3 * sigma * k3), 0.5 * (-b + d), 0.5 * (-b - d)):
        s = np.sqrt(x)
        out += [s, -s]
    return np.array(out)


@dataclass(frozen=True)
class AttitudeEquilibrium:
    """The linearised attitude of a body held at a collinear point (see the module docs).

    ``q0`` (scalar last, body relative to synodic) and ``w0`` (inertial, body axes) give the
    equilibrium; ``matrix`` is the 6x6 d(theta, dw)/dt of the Rust model's exact Jacobian in
    body-axis coordinates; ``eigenvalues`` its six eigenvalues; ``stable``: every eigenvalue
    imaginary to :data:`STABILITY_TOL` (the linear test: a double pair on a boundary counts as
    stable here though it grows secularly). ``sigma``: (1 - mu)/r1^3 + mu/r2^3 at the point;
    ``moments_synodic``: the moments about the synodic X, Y, Z axes; ``residual``: the largest
    attitude derivative at the equilibrium (zero up to rounding)."""

    system: System
    point: int
    body: RigidBody
    q0: np.ndarray
    w0: np.ndarray
    position: np.ndarray
    sigma: float
    moments_synodic: tuple[float, float, float]
    matrix: np.ndarray = field(repr=False)
    eigenvalues: np.ndarray = field(repr=False)
    residual: float = 0.0

    @property
    def h(self) -> float:
        """The thesis's h = 3 sigma (Table 4)."""
        return 3.0 * self.sigma

    @property
    def stable(self) -> bool:
        s = self.eigenvalues
        return bool(np.all(np.abs(s.real) <= STABILITY_TOL * np.maximum(1.0, np.abs(s))))

    @property
    def ratios(self) -> tuple[float, float, float]:
        """(K1, K2, K3) of :func:`inertia_ratios` about the synodic axes."""
        return inertia_ratios(self.moments_synodic)

    def closed_form(self) -> np.ndarray:
        """The eigenvalues from the closed-form polynomial (:func:`closed_form_eigenvalues`)."""
        return closed_form_eigenvalues(self.sigma, self.moments_synodic)


def attitude_equilibrium(system: System | str, point, body: RigidBody, q0=None) -> AttitudeEquilibrium:
    """The linearised 3-D attitude of a body held at a collinear Lagrange point, its principal axes
    on the synodic axes, under the gravity gradient of both primaries.

    Parameters
    ----------
    system : System or str
        The system.
    point : {1, 2, 3}
        The collinear point.
    body : RigidBody
        The body (every moment > 0).
    q0 : array_like, shape (4,), optional
        The equilibrium attitude, scalar last, body relative to synodic (default the identity:
        body x, y, z on synodic X, Y, Z); any signed permutation of the axes is accepted.

    Returns
    -------
    AttitudeEquilibrium
        The 6x6 matrix, its eigenvalues, ``stable`` and the moments about the synodic axes.

    Raises
    ------
    ValueError
        A bad point, body or q0 (not a signed axis permutation).

    Examples
    --------
    >>> import librate
    >>> eq = librate.attitude_equilibrium("earth-moon", 1, librate.RigidBody(1.0, 2.0, 2.5))
    >>> eq.eigenvalues.shape
    (6,)
    """
    sys_ = resolve_system(system)
    k = _point(point)
    if not isinstance(body, RigidBody) or body.is_rod:
        raise ValueError(f"invalid argument `body`: must be a librate.RigidBody with every principal moment > 0, got {body!r}")
    q = np.array([0.0, 0.0, 0.0, 1.0]) if q0 is None else np.asarray(q0, dtype=np.float64).ravel()
    if q.shape != (4,) or not np.all(np.isfinite(q)):
        raise ValueError(f"invalid argument `q0`: must be 4 finite numbers (a scalar-last quaternion), got {q0!r}")
    r = _core.attitude_equilibrium(sys_.mu, list(body.moments), k, [float(v) for v in q])
    state = np.asarray(r.state)
    a = _dcm(state[6:10])
    moments = tuple(float(v) for v in (a * a).T @ np.asarray(body.moments))
    m = np.asarray(r.matrix)
    return AttitudeEquilibrium(sys_, k, body, state[6:10], state[10:], state[:3], float(r.sigma), moments, m, np.linalg.eigvals(m),
                               float(r.residual))


def _dcm(q) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(q).as_matrix().T  # synodic -> body


def moments_from_ratios(k_x, k_y):
    """Moments (Ix, Iy, Iz) with Iz = 1 of Robinson's ratios k_x = (Iy - Iz)/Ix and
    k_y = (Iz - Ix)/Iy (thesis Fig. 19 axes), |k_x|, |k_y| < 1 (arrays broadcast)."""
    k1, k2 = -np.asarray(k_x, dtype=float), np.asarray(k_y, dtype=float)
    den = 1 - k1 * k2
    return (1 - k2) / den, (1 - k1) / den, np.ones(np.broadcast(k1, k2).shape)


def equilibrium_stability(system: System | str, point, *, n: int = 401, k_range: tuple[float, float] = (-1.0, 1.0)):
    """The linear stability of the equilibrium attitude at a collinear point over the plane of
    Robinson's inertia ratios (thesis Fig. 19).

    k_x = (Iy - Iz) / Ix and k_y = (Iz - Ix) / Iy are sampled on an ``n`` x ``n`` grid of the
    open square ``k_range`` (ends excluded: |k| = 1 are thin rods), from the closed-form
    characteristic polynomial s^4 + b s^2 + c of the roll-yaw motion and the pitch term.

    Parameters
    ----------
    system : System or str
        The system.
    point : {1, 2, 3}
        The collinear point.
    n : int, default 401
        Samples per axis.
    k_range : (float, float), default (-1, 1)
        The square's range.

    Returns
    -------
    xarray.Dataset
        Over (k_y, k_x): ``stable`` (bool), ``pitch_stable`` (K3 > 0, the decoupled rotation about
        Z), ``roll_yaw`` (a code of ``ROLL_YAW_REGIONS``), ``max_real`` (the largest real part of
        the six eigenvalues, 1/TU), ``b`` and ``c``; attributes: the point, sigma, h.
    """
    import xarray as xr

    sys_ = resolve_system(system)
    k = _point(point)
    n = as_count(n, "n", 3)
    try:
        lo, hi = (float(v) for v in k_range)
    except (TypeError, ValueError):
        raise ValueError(f"invalid argument `k_range`: must be (lo, hi), got {k_range!r}") from None
    if not (-1 <= lo < hi <= 1):
        raise ValueError(f"invalid argument `k_range`: must satisfy -1 <= lo < hi <= 1, got {k_range!r}")
    ks = np.linspace(lo, hi, n + 2)[1:-1]
    sigma = attitude_equilibrium(sys_, k, RigidBody(1.0, 1.0, 1.0)).sigma
    kx, ky = np.meshgrid(ks, ks)
    a, b_, c_ = moments_from_ratios(kx, ky)
    k1, k2, k3 = (c_ - b_) / a, (c_ - a) / b_, (b_ - a) / c_
    b = 1 + 3 * sigma * k2 + k1 * k2
    c = (1 + 3 * sigma) * k1 * k2
    disc = b * b - 4 * c
    roll_yaw = np.where((c > 0) & (b > 0) & (disc > 0), 0, np.where(disc >= 0, 1, 2))
    # largest real part: pitch sqrt(max(0, -3 sigma K3)); roll-yaw from s^2 = (-b +- sqrt(disc)) / 2
    sq = np.sqrt(disc.astype(complex))
    re = np.maximum(np.abs(np.sqrt(0.5 * (-b + sq)).real), np.abs(np.sqrt(0.5 * (-b - sq)).real))
    max_real = np.maximum(re, np.sqrt(np.maximum(0.0, -3 * sigma * k3)))
    pitch = k3 > 0
    return xr.Dataset(
        {"stable": (("k_y", "k_x"), pitch & (roll_yaw == 0)), "pitch_stable": (("k_y", "k_x"), pitch),
         "roll_yaw": (("k_y", "k_x"), roll_yaw.astype(np.int8)), "max_real": (("k_y", "k_x"), max_real),
         "b": (("k_y", "k_x"), b), "c": (("k_y", "k_x"), c)},
        coords={"k_x": ("k_x", ks, {"long_name": "(Iy - Iz) / Ix"}), "k_y": ("k_y", ks, {"long_name": "(Iz - Ix) / Iy"})},
        attrs={"point": f"L{k}", "sigma": sigma, "h": 3 * sigma, "mu": sys_.mu, "system": sys_.name,
               "roll_yaw_codes": "; ".join(f"{k_}: {v}" for k_, v in ROLL_YAW_REGIONS.items()),
               "reference": "Robinson (1974), Celest. Mech. 10, 17-33; Kane & Marsh (1971), Celest. Mech. 4, 78-90"})

