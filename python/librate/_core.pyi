"""Type stubs of the private Rust extension. Use the `librate` package API instead."""

from typing import Any, TypedDict, final

import numpy as np
import numpy.typing as npt

__version__: str
__all__ = [
    "CollisionError",
    "ConvergenceError",
    "IntegrationError",
    "LibrateError",
    "OrbitForcing",
    "__version__",
    "attitude_propagate",
    "attitude_torques",
    "facets_force_torque",
    "flexible_body_check",
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
    "planar_propagate",
    "preset_names",
    "propagate",
    "propagate_many",
    "rigid_body_kz",
    "stability",
    "symmetric_correct",
    "symmetric_evaluate",
    "system_preset",
    "system_validate",
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
def symmetric_evaluate(mu: float, p: list[float], *, spatial: bool, t_max: float, rtol: float, atol: float) -> dict[str, Any]: ...
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

def map_sweep(
    forcing: OrbitForcing, t_final: float, phi0: _F64, wz0: _F64, kz: _F64, *,
    rtol: float, atol: float, max_steps: int, stm: bool, chunk: int, threads: int | None,
    eps: _F64 | None = None, cs: _F64 | None = None, cd: _F64 | None = None, theta_sun0: _F64 | None = None,
) -> dict[str, Any]: ...

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
