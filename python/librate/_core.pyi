"""Type stubs of the private Rust extension. Use the `librate` package API instead."""

from typing import Any, TypedDict, final

import numpy as np
import numpy.typing as npt

__version__: str
#: Physical constants of the core (librate_core::constants).
N_SUN: float
OMEGA_SUN: float
SOLAR_PRESSURE_1AU: float
SUN_SYNODIC_PERIOD: float
__all__ = [
    "CollisionError",
    "ConvergenceError",
    "CorrectionBatch",
    "IntegrationError",
    "LibrateError",
    "N_SUN",
    "OMEGA_SUN",
    "OrbitForcing",
    "PlanarFamily",
    "PlanarVerification",
    "SOLAR_PRESSURE_1AU",
    "SUN_SYNODIC_PERIOD",
    "SweepResult",
    "__version__",
    "attitude_correct",
    "attitude_correct_across",
    "build_info",
    "attitude_propagate",
    "attitude_torques",
    "facets_force_torque",
    "flat_plate_wzdot",
    "flexible_body_check",
    "flexible_correct_periodic",
    "flexible_energies",
    "flexible_propagate",
    "flexible_quasi_static",
    "flexible_quasi_static_point",
    "flexible_rates",
    "fourier_evaluate",
    "jacobi",
    "lagrange_points",
    "map_sweep",
    "multiple_shooting",
    "planar_gravity_gradient",
    "planar_propagate",
    "planar_verify",
    "preset_names",
    "propagate",
    "propagate_many",
    "rigid_body_kz",
    "stability",
    "sun_angle",
    "symmetric_correct",
    "system_preset",
    "system_validate",
    "simd_set_active",
]

class LibrateError(Exception): ...

class IntegrationError(LibrateError):
    t: float
    steps: int
    kind: str

class CollisionError(IntegrationError):
    primary: int
    distance: float
    radius: float

class ConvergenceError(LibrateError):
    iterations: int
    residual: float
    tolerance: float

_F64 = npt.NDArray[np.float64]

class _BuildInfo(TypedDict):
    simd_known: list[str]
    simd_available: list[str]
    simd_active: str
    version: str
    profile: str
    target_arch: str

def build_info() -> _BuildInfo: ...
def simd_set_active(level: str) -> str: ...

class _Options(TypedDict):
    rtol: float
    atol: float
    h0: float | None
    h_min: float
    h_max: float
    max_steps: int
    safety: float
    fixed_step: float | None

def propagate(
    mu: float,
    state: _F64,
    t0: float,
    tf: float,
    *,
    options: _Options,
    stm: bool,
    t_eval: _F64 | None,
    events: list[tuple[str, list[float], int, bool]],
    collision: tuple[float, float] | None = None,
) -> dict[str, Any]: ...
def propagate_many(
    mu: float,
    states: _F64,
    t0: float,
    t_final: _F64,
    *,
    options: _Options,
    stm: bool,
    threads: int | None,
    collision: tuple[float, float] | None = None,
) -> dict[str, Any]: ...
def jacobi(mu: float, states: _F64) -> _F64: ...
def lagrange_points(mu: float) -> _F64: ...
def system_preset(name: str) -> tuple[str, float, float, float, float, float]: ...
def system_validate(name: str, mu: float, lu_km: float, tu_s: float, r1_km: float, r2_km: float) -> tuple[str, float, float, float, float, float]: ...
def preset_names() -> list[str]: ...
def symmetric_correct(
    mu: float, p: list[float], *, spatial: bool, constraint: str, values: list[float], tol: float, max_iter: int, t_max: float, rtol: float, atol: float
) -> dict[str, Any]: ...
def stability(m: _F64, planar: bool) -> tuple[npt.NDArray[np.complex128], npt.NDArray[np.complex128]]: ...
def multiple_shooting(
    mu: float, patches: _F64, period: float, *, condition: str, value: float, tol: float, max_iter: int, rtol: float, atol: float
) -> dict[str, Any]: ...
def fourier_evaluate(
    period: float, a0: _F64, cos: _F64, sin: _F64, t: _F64, *, quantity: str
) -> _F64: ...
_FacetTuple = tuple[float, list[float], list[float], float, float, float]

def attitude_propagate(
    mu: float, inertia: list[float], torques: list[str], orbit_mode: str, state0: list[float], t0: float, tf: float, *,
    options: _Options, stm: bool, t_eval: _F64 | None, inertia_nd: list[float] | None = None,
    facets: list[_FacetTuple] | None = None, sun: tuple[float, float, float] = ..., tu_s: float = 1.0,
    srp_force: tuple[float, float] | None = None,
) -> dict[str, Any]: ...
def facets_force_torque(facets: list[_FacetTuple], s_body: list[float]) -> tuple[list[float], list[float]]: ...
def planar_propagate(
    mu: float, kz: float, primaries: list[bool], held: bool, orbit0: list[float], phi0: float, wz0: float, t0: float, tf: float, *,
    options: _Options, stm: bool, t_eval: _F64 | None, plate: tuple[float, float, float, float, float] | None = None
) -> dict[str, Any]: ...
def attitude_torques(mu: float, inertia: list[float], torques: list[str], t: _F64, states: _F64) -> _F64: ...
def rigid_body_kz(ix: float, iy: float, iz: float) -> float: ...

@final
class OrbitForcing:
    def __new__(cls, mu: float, state0: list[float], period: float, *, primaries: list[bool] = ..., tol: float = 1e-12) -> OrbitForcing: ...
    @property
    def period(self) -> float: ...
    @property
    def segments(self) -> int: ...
    @property
    def max_error(self) -> float: ...
    def sc(self, t: _F64) -> tuple[_F64, _F64]: ...

@final
class SweepResult:
    @property
    def phi_t(self) -> _F64: ...
    @property
    def wz_t(self) -> _F64: ...
    @property
    def dwz(self) -> _F64: ...
    @property
    def dphi(self) -> _F64: ...
    @property
    def stm(self) -> _F64 | None: ...
    @property
    def status(self) -> npt.NDArray[np.uint8]: ...
    @property
    def steps(self) -> npt.NDArray[np.uint32]: ...
    def __getitem__(self, name: str, /) -> Any: ...
    def keys(self) -> list[str]: ...
    def __len__(self) -> int: ...

def map_sweep(
    forcing: OrbitForcing, t_final: float, phi0: _F64, wz0: _F64, kz: _F64, *,
    rtol: float, atol: float, max_steps: int, stm: bool, chunk: int, threads: int | None,
    eps: _F64 | None = None, cs: _F64 | None = None, cd: _F64 | None = None, theta_sun0: _F64 | None = None,
) -> SweepResult: ...

@final
class CorrectionBatch:
    @property
    def phi0(self) -> _F64: ...
    @property
    def wz0(self) -> _F64: ...
    @property
    def theta_sun0(self) -> _F64: ...
    @property
    def residual(self) -> _F64: ...
    @property
    def residual_norm(self) -> _F64: ...
    @property
    def iterations(self) -> npt.NDArray[np.int64]: ...
    @property
    def converged(self) -> npt.NDArray[np.bool_]: ...
    @property
    def reason(self) -> list[str]: ...
    @property
    def monodromy(self) -> _F64: ...
    @property
    def parameter(self) -> _F64: ...
    @property
    def jacobian(self) -> _F64: ...
    def __len__(self) -> int: ...

def attitude_correct(
    forcing: OrbitForcing, phi0: _F64, wz0: _F64, kz: _F64, turns: _F64, *,
    t_final: float, closure: str, free: str = "phi0",
    eps: _F64 | None = None, cs: _F64 | None = None, cd: _F64 | None = None, theta_sun0: _F64 | None = None,
    tol: float = 1e-12, max_iter: int = 40, rtol: float = 1e-13, atol: float = 1e-13, max_steps: int = 200000,
    max_wz_step: float = 0.5, max_angle_step: float = 0.5, threads: int | None = None, chunk: int = 64,
    parameter: str | None = None, condition: tuple[float, float, float, float] | None = None,
    parameter_step: float = 1e-6, max_parameter_step: float = 0.5, monodromy: bool = True, max_halvings: int = 10,
) -> CorrectionBatch: ...

@final
class PlanarFamily:
    def __new__(cls, mu: float, x0: list[float], vy0: list[float]) -> PlanarFamily: ...
    @property
    def range(self) -> tuple[float, float]: ...
    def orbit_at(self, x0: float) -> tuple[list[float], float]: ...

def attitude_correct_across(
    family: PlanarFamily, wz0: _F64, kz: _F64, turns: _F64, x0: _F64, *,
    condition: tuple[float, float, float], phi0: float = 0.0, tol: float = 1e-12, max_iter: int = 40, rtol: float = 1e-13,
    atol: float = 1e-13, max_steps: int = 200000, max_wz_step: float = 0.5, parameter_step: float = 1e-6,
    max_parameter_step: float = 0.05, threads: int | None = None, max_halvings: int = 10,
) -> CorrectionBatch: ...

@final
class PlanarVerification:
    @property
    def phi_t(self) -> _F64: ...
    @property
    def wz_t(self) -> _F64: ...
    @property
    def stm(self) -> _F64: ...
    @property
    def error(self) -> list[str | None]: ...
    def __len__(self) -> int: ...

def planar_verify(
    mu: float, orbit_state0: list[float], t_final: float, kz: _F64, phi0: _F64, wz0: _F64, *,
    eps: _F64 | None = None, cs: _F64 | None = None, cd: _F64 | None = None, theta_sun0: _F64 | None = None,
    primaries: list[bool] = ..., threads: int | None = None,
) -> PlanarVerification: ...

_FlexBody = tuple[float, list[float], list[tuple[float, list[float], list[float], float, float]]]

def flexible_body_check(body_arg: _FlexBody) -> dict[str, Any]: ...
def flexible_propagate(
    mu: float, body_arg: _FlexBody, primaries: list[bool], held: bool, orbit0: list[float], phi0: float, wz0: float,
    q0: list[float], qdot0: list[float], t0: float, tf: float, *, options: _Options, t_eval: _F64 | None
) -> dict[str, Any]: ...
def flexible_quasi_static(
    mu: float, body_arg: _FlexBody, primaries: list[bool], held: bool, orbit0: list[float], phi0: float, wz0: float,
    t0: float, tf: float, *, options: _Options, t_eval: _F64 | None
) -> dict[str, Any]: ...
def flexible_quasi_static_point(
    mu: float, body_arg: _FlexBody, primaries: list[bool], held: bool, orbit: list[float], phi: float, wz: float
) -> tuple[list[float], list[float], list[float], float, float]: ...
def flexible_energies(
    mu: float, body_arg: _FlexBody, primaries: list[bool], orbit: _F64, phi: _F64, wz: _F64, q: _F64, qdot: _F64
) -> dict[str, _F64]: ...
def flexible_rates(
    mu: float, body_arg: _FlexBody, primaries: list[bool], orbit: list[float], phi: float, wz: float, q: list[float], qdot: list[float]
) -> tuple[float, list[float]]: ...

def planar_gravity_gradient(kz: float, s: _F64, c: _F64, phi: _F64) -> _F64: ...
def flat_plate_wzdot(eps: float, cs: float, cd: float, theta_sun0: float, t: _F64, phi: _F64) -> _F64: ...
def sun_angle(theta_sun0: float, t: _F64) -> _F64: ...
def flexible_correct_periodic(
    mu: float, body_arg: Any, primaries: list[bool], orbit0: list[float], period: float, x0: list[float], turns: float,
    scale: list[float], *, options: Any, tol: float, max_iter: int, threads: int | None = None,
) -> tuple[_F64, float, int, str, _F64]: ...
