"""Type stubs of the private Rust extension. Use the `librate` package API instead."""

from collections.abc import Sequence
from typing import Any, Literal, TypedDict, final

import numpy as np
import numpy.typing as npt

__version__: str
#: Physical constants of the core (librate_core::constants).
N_SUN: float
OMEGA_SUN: float
SOLAR_PRESSURE_1AU: float
SUN_SYNODIC_PERIOD: float
__all__ = [
    "AttitudeTrajectory",
    "BatchResult",
    "CollisionError",
    "ConvergenceError",
    "CorrectionBatch",
    "EventHit",
    "FlexibleBodyConstants",
    "FlexibleEnergies",
    "FlexiblePeriodicCorrection",
    "FlexibleTrajectory",
    "IntegrationError",
    "LibrateError",
    "MultipleShooting",
    "N_SUN",
    "OMEGA_SUN",
    "OrbitForcing",
    "PlanarFamily",
    "PlanarTrajectory",
    "PlanarVerification",
    "QuasiStaticPoint",
    "QuasiStaticTrajectory",
    "SOLAR_PRESSURE_1AU",
    "SUN_SYNODIC_PERIOD",
    "ShootingEvaluation",
    "Stats",
    "SweepResult",
    "SymmetricOrbit",
    "SystemConstants",
    "Trajectory",
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

class LibrateError(Exception):
    """The base class of librate's errors: ``except librate.LibrateError`` catches them all."""

class IntegrationError(LibrateError):
    """An integration stopped before its final time: step-size underflow, too many steps, a
    non-finite state.

    Attributes
    ----------
    t : float
        The time reached (TU).
    steps : int
        The steps taken.
    kind : str
        What stopped it.
    """

    t: float
    steps: int
    kind: str

class CollisionError(IntegrationError):
    """The trajectory reached a primary: its radius, or a tiny sphere (1e-8 LU) for point masses.

    Attributes
    ----------
    primary : int
        1 (the larger) or 2.
    distance : float
        The distance from the primary's centre where it stopped (LU).
    radius : float
        The collision radius (LU).
    """

    primary: int
    distance: float
    radius: float

class ConvergenceError(LibrateError):
    """An iterative solver (a Newton corrector, a continuation) did not converge.

    Attributes
    ----------
    iterations : int
        The iterations done.
    residual : float
        The last residual.
    tolerance : float
        The tolerance asked.
    """

    iterations: int
    residual: float
    tolerance: float

_F64 = npt.NDArray[np.float64]
_I64 = npt.NDArray[np.int64]

class _BuildInfo(TypedDict):
    simd_known: list[str]
    simd_available: list[str]
    simd_active: str
    version: str
    profile: str
    debug_assertions: bool
    target_arch: str

def build_info() -> _BuildInfo: ...
def simd_set_active(level: str) -> str: ...

# --- typed arguments (rust/py/src/options.rs) ---
__all__ += ["IntegrationOptions", "NewtonOptions", "LaneMethod", "LaneOptions", "CorrectorOptions", "CorrectorOptions3D", "Closure", "Free",
            "BorderedParameter", "Bordered", "Plates", "PlanarCases", "AttitudeCases3D"]

@final
class IntegrationOptions:
    def __new__(
        cls, *, rtol: float = 1e-12, atol: float = 1e-12, h0: float | None = None, h_min: float = 0.0, h_max: float = ...,
        max_steps: int = 1000000, safety: float | None = None, fixed_step: float | None = None,
    ) -> IntegrationOptions: ...
    @property
    def rtol(self) -> float: ...
    @property
    def atol(self) -> float: ...
    @property
    def h0(self) -> float | None: ...
    @property
    def h_min(self) -> float: ...
    @property
    def h_max(self) -> float: ...
    @property
    def max_steps(self) -> int: ...
    @property
    def safety(self) -> float: ...
    @property
    def fixed_step(self) -> float | None: ...

@final
class NewtonOptions:
    def __new__(
        cls, *, tol: float = 1e-12, max_iter: int = 40, max_halvings: int = 10, max_angle_step: float = 0.5, max_rate_step: float = 0.5,
        max_contraction: float | None = None,
    ) -> NewtonOptions: ...
    @property
    def tol(self) -> float: ...
    @property
    def max_iter(self) -> int: ...
    @property
    def max_halvings(self) -> int: ...
    @property
    def max_angle_step(self) -> float: ...
    @property
    def max_rate_step(self) -> float: ...
    @property
    def max_contraction(self) -> float | None: ...

@final
class LaneMethod:
    RKF78: LaneMethod
    RKN86: LaneMethod
    DP87: LaneMethod
    def __int__(self) -> int: ...

@final
class LaneOptions:
    def __new__(
        cls, *, rtol: float = 1e-12, atol: float = 1e-12, max_steps: int = 200000, method: LaneMethod = ..., chunk: int = 64,
        threads: int | None = None,
    ) -> LaneOptions: ...
    @property
    def rtol(self) -> float: ...
    @property
    def atol(self) -> float: ...
    @property
    def max_steps(self) -> int: ...
    @property
    def method(self) -> LaneMethod: ...
    @property
    def chunk(self) -> int: ...
    @property
    def threads(self) -> int | None: ...

@final
class CorrectorOptions:
    def __new__(cls, newton: NewtonOptions, lanes: LaneOptions, *, monodromy: bool = True) -> CorrectorOptions: ...
    @property
    def newton(self) -> NewtonOptions: ...
    @property
    def lanes(self) -> LaneOptions: ...
    @property
    def monodromy(self) -> bool: ...

@final
class CorrectorOptions3D:
    def __new__(
        cls, newton: NewtonOptions, *, rtol: float = 1e-13, atol: float = 1e-13, primaries: list[bool] = ..., half: bool = False,
        max_period_step: float = 0.5, threads: int | None = None,
    ) -> CorrectorOptions3D: ...
    @property
    def newton(self) -> NewtonOptions: ...
    @property
    def rtol(self) -> float: ...
    @property
    def atol(self) -> float: ...
    @property
    def primaries(self) -> list[bool]: ...
    @property
    def half(self) -> bool: ...
    @property
    def max_period_step(self) -> float: ...
    @property
    def threads(self) -> int | None: ...

@final
class Closure:
    HALF: Closure
    FULL: Closure
    def __int__(self) -> int: ...

@final
class Free:
    PHI0: Free
    SUN_PHASE: Free
    def __int__(self) -> int: ...

@final
class BorderedParameter:
    KZ: BorderedParameter
    EPS: BorderedParameter
    ORBIT_X0: BorderedParameter
    def __int__(self) -> int: ...

@final
class Bordered:
    def __new__(
        cls, parameter: BorderedParameter, condition: tuple[float, float, float, float], *, step: float = 1e-6, max_step: float = 0.5,
        conditions: _F64 | None = None,
    ) -> Bordered: ...

@final
class Plates:
    def __new__(cls, eps: _F64, cs: _F64, cd: _F64, theta_sun0: _F64) -> Plates: ...
    def __len__(self) -> int: ...

@final
class PlanarCases:
    def __new__(
        cls, phi0: _F64, wz0: _F64, kz: _F64, *, turns: _F64 | None = None, plates: Plates | None = None, window: _F64 | None = None
    ) -> PlanarCases: ...
    def __len__(self) -> int: ...

@final
class AttitudeCases3D:
    def __new__(
        cls, q: _F64, w: _F64, *, period: _F64 | None = None, a: _F64 | None = None, b: _F64 | None = None
    ) -> AttitudeCases3D: ...
    def __len__(self) -> int: ...

@final
class Stats:
    @property
    def accepted(self) -> int: ...
    @property
    def rejected(self) -> int: ...
    @property
    def rhs_evals(self) -> int: ...

@final
class EventHit:
    @property
    def index(self) -> int: ...
    @property
    def t(self) -> float: ...
    @property
    def y(self) -> _F64: ...
    @property
    def stm(self) -> _F64 | None: ...

@final
class Trajectory:
    @property
    def t(self) -> _F64: ...
    @property
    def y(self) -> _F64: ...
    @property
    def t_final(self) -> float: ...
    @property
    def y_final(self) -> _F64: ...
    @property
    def stm(self) -> _F64 | None: ...
    @property
    def events(self) -> tuple[EventHit, ...]: ...
    @property
    def status(self) -> Literal["completed", "event", "collision"]: ...
    @property
    def event_index(self) -> int | None: ...
    @property
    def collision(self) -> CollisionError | None: ...
    @property
    def stats(self) -> Stats: ...
    def __len__(self) -> int: ...

@final
class BatchResult:
    @property
    def y(self) -> _F64: ...
    @property
    def stm(self) -> _F64 | None: ...
    @property
    def ok(self) -> npt.NDArray[np.bool_]: ...
    @property
    def status(self) -> npt.NDArray[np.uint8]: ...
    @property
    def errors(self) -> dict[int, Exception]: ...
    @property
    def stats(self) -> npt.NDArray[np.uint64]: ...
    def __len__(self) -> int: ...

def propagate(
    mu: float,
    state: _F64,
    t_span: tuple[float, float],
    *,
    options: IntegrationOptions,
    stm: bool,
    t_eval: _F64 | None,
    events: list[tuple[str, list[float], int, bool]],
    collision: tuple[float, float] | None = None,
) -> Trajectory: ...
def propagate_many(
    mu: float,
    states: _F64,
    t0: float,
    t_final: _F64,
    *,
    options: IntegrationOptions,
    stm: bool,
    threads: int | None,
    collision: tuple[float, float] | None = None,
) -> BatchResult: ...
def jacobi(mu: float, states: _F64) -> _F64: ...
def lagrange_points(mu: float) -> _F64: ...
@final
class SystemConstants:
    @property
    def name(self) -> str: ...
    @property
    def mu(self) -> float: ...
    @property
    def lu_km(self) -> float: ...
    @property
    def tu_s(self) -> float: ...
    @property
    def r1_km(self) -> float: ...
    @property
    def r2_km(self) -> float: ...

def system_preset(name: str) -> SystemConstants: ...
def system_validate(name: str, mu: float, lu_km: float, tu_s: float, r1_km: float, r2_km: float) -> SystemConstants: ...
def preset_names() -> list[str]: ...
@final
class ShootingEvaluation:
    @property
    def p(self) -> _F64: ...
    @property
    def cond(self) -> _F64: ...
    @property
    def dcond(self) -> _F64: ...
    @property
    def half_period(self) -> float: ...
    @property
    def dhalf(self) -> _F64: ...
    @property
    def jacobi(self) -> float: ...
    @property
    def djacobi(self) -> _F64: ...
    @property
    def crossing(self) -> _F64: ...
    @property
    def monodromy(self) -> _F64 | None: ...

@final
class SymmetricOrbit:
    @property
    def state0(self) -> _F64: ...
    @property
    def period(self) -> float: ...
    @property
    def jacobi(self) -> float: ...
    @property
    def iterations(self) -> int: ...
    @property
    def residual(self) -> float: ...
    @property
    def evaluation(self) -> ShootingEvaluation: ...

@final
class MultipleShooting:
    @property
    def patches(self) -> _F64: ...
    @property
    def period(self) -> float: ...
    @property
    def jacobi(self) -> float: ...
    @property
    def iterations(self) -> int: ...
    @property
    def residual(self) -> float: ...

def symmetric_correct(
    mu: float, p: list[float], *, spatial: bool, constraint: str, values: list[float], t_max: float, newton: NewtonOptions,
    options: IntegrationOptions
) -> SymmetricOrbit: ...
def stability(m: _F64, planar: bool) -> tuple[npt.NDArray[np.complex128], npt.NDArray[np.complex128]]: ...
def multiple_shooting(
    mu: float, patches: _F64, period: float, *, condition: str, value: float, newton: NewtonOptions, options: IntegrationOptions
) -> MultipleShooting: ...
def fourier_evaluate(
    period: float, a0: _F64, cos: _F64, sin: _F64, t: _F64, *, quantity: str
) -> _F64: ...
_FacetTuple = tuple[float, list[float], list[float], float, float, float]

@final
class AttitudeTrajectory:
    @property
    def t(self) -> _F64: ...
    @property
    def states(self) -> _F64: ...
    @property
    def stm(self) -> _F64 | None: ...
    @property
    def stats(self) -> Stats: ...
    def __len__(self) -> int: ...

@final
class PlanarTrajectory:
    @property
    def t(self) -> _F64: ...
    @property
    def orbit(self) -> _F64: ...
    @property
    def phi(self) -> _F64: ...
    @property
    def wz(self) -> _F64: ...
    @property
    def stm(self) -> _F64 | None: ...
    @property
    def stats(self) -> Stats: ...
    def __len__(self) -> int: ...

__all__ += ["OrbitMode", "SrpModel", "AttitudeModel", "PlanarModel", "FlexibleModel"]

@final
class OrbitMode:
    INTEGRATE: OrbitMode
    HELD: OrbitMode
    COUPLED: OrbitMode
    def __int__(self) -> int: ...

@final
class SrpModel:
    def __new__(
        cls, facets: list[_FacetTuple], *, sun: tuple[float, float, float] = ..., tu_s: float = 1.0,
        force: tuple[float, float] | None = None
    ) -> SrpModel: ...

@final
class AttitudeModel:
    def __new__(
        cls, mu: float, inertia: list[float], torques: list[str], *, orbit: OrbitMode = ..., inertia_nd: list[float] | None = None,
        srp: SrpModel | None = None,
    ) -> AttitudeModel: ...

@final
class PlanarModel:
    def __new__(
        cls, mu: float, kz: float, *, primaries: list[bool] = ..., held: bool = False,
        plate: tuple[float, float, float, float, float] | None = None
    ) -> PlanarModel: ...

def attitude_propagate(
    model: AttitudeModel, state0: list[float], t_span: tuple[float, float], *, options: IntegrationOptions, stm: bool, t_eval: _F64 | None
) -> AttitudeTrajectory: ...
def facets_force_torque(facets: list[_FacetTuple], s_body: list[float]) -> tuple[list[float], list[float]]: ...
def planar_propagate(
    model: PlanarModel, orbit0: list[float], attitude0: tuple[float, float], t_span: tuple[float, float], *,
    options: IntegrationOptions, stm: bool, t_eval: _F64 | None
) -> PlanarTrajectory: ...
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

def map_sweep(forcing: OrbitForcing, t_final: float, cases: PlanarCases, *, lanes: LaneOptions, stm: bool) -> SweepResult: ...

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
    forcing: OrbitForcing, cases: PlanarCases, *, t_final: float, closure: Closure, free: Free, options: CorrectorOptions,
    bordered: Bordered | None = None,
) -> CorrectionBatch: ...

@final
class PlanarFamily:
    def __new__(cls, mu: float, x0: list[float], vy0: list[float]) -> PlanarFamily: ...
    @property
    def range(self) -> tuple[float, float]: ...
    def orbit_at(self, x0: float) -> tuple[list[float], float]: ...

def attitude_correct_across(
    family: PlanarFamily, cases: PlanarCases, x0: _F64, *, bordered: Bordered, options: CorrectorOptions
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
    def residual(self) -> _F64: ...
    @property
    def error(self) -> list[str | None]: ...
    def __len__(self) -> int: ...

def planar_verify(
    mu: float, orbit_state0: list[float], t_final: float, cases: PlanarCases, *, primaries: list[bool] = ..., threads: int | None = None
) -> PlanarVerification: ...

__all__ += ["PlanarRefinement", "PendingRefinement", "attitude_refine", "RowCrossings", "row_crossings", "distinct_solutions"]

def distinct_solutions(groups: _I64, kz: _F64, turns: _F64, wz0: _F64) -> _I64: ...

@final
class PlanarRefinement:
    @property
    def index(self) -> _I64: ...
    @property
    def phi0(self) -> _F64: ...
    @property
    def wz0(self) -> _F64: ...
    @property
    def iterations(self) -> _I64: ...
    @property
    def phi_t(self) -> _F64: ...
    @property
    def wz_t(self) -> _F64: ...
    @property
    def stm(self) -> _F64: ...
    @property
    def residual(self) -> _F64: ...
    def __len__(self) -> int: ...

@final
class PendingRefinement:
    def join(self) -> PlanarRefinement: ...

def attitude_refine(
    forcing: OrbitForcing, cases: PlanarCases, *, t_final: float, closure: Closure, options: CorrectorOptions, keep: tuple[float, float],
    groups: _I64 | None = None,
) -> PendingRefinement: ...

@final
class RowCrossings:
    @property
    def k(self) -> _I64: ...
    @property
    def wz0(self) -> _F64: ...
    @property
    def interval(self) -> _I64: ...
    @property
    def window(self) -> _F64 | None: ...
    @property
    def unresolved(self) -> int: ...

def row_crossings(
    phi_t: _F64, wz0: _F64, *, phi0: float, level: float, max_crossings: int | None = None, window: tuple[int, float] | None = None
) -> RowCrossings: ...

_FlexBody = tuple[float, list[float], list[tuple[float, list[float], list[float], float, float]]]

@final
class FlexibleBodyConstants:
    @property
    def total_mass(self) -> float: ...
    @property
    def hub_position(self) -> list[float]: ...
    @property
    def inertia(self) -> float: ...
    @property
    def asymmetry(self) -> complex: ...
    @property
    def kz(self) -> float: ...
    @property
    def principal_angle(self) -> float: ...
    @property
    def mass_matrix(self) -> _F64: ...
    @property
    def directions(self) -> list[list[float]]: ...

@final
class FlexibleTrajectory:
    @property
    def t(self) -> _F64: ...
    @property
    def orbit(self) -> _F64: ...
    @property
    def phi(self) -> _F64: ...
    @property
    def wz(self) -> _F64: ...
    @property
    def q(self) -> _F64: ...
    @property
    def qdot(self) -> _F64: ...
    @property
    def stats(self) -> Stats: ...
    def __len__(self) -> int: ...

@final
class QuasiStaticTrajectory:
    @property
    def t(self) -> _F64: ...
    @property
    def orbit(self) -> _F64: ...
    @property
    def phi(self) -> _F64: ...
    @property
    def wz(self) -> _F64: ...
    @property
    def dphi(self) -> _F64: ...
    @property
    def dwz(self) -> _F64: ...
    @property
    def q(self) -> _F64: ...
    @property
    def qdot(self) -> _F64: ...
    @property
    def qddot(self) -> _F64: ...
    @property
    def dtau(self) -> _F64: ...
    @property
    def stats(self) -> Stats: ...
    def __len__(self) -> int: ...

@final
class FlexibleEnergies:
    @property
    def kinetic(self) -> _F64: ...
    @property
    def elastic(self) -> _F64: ...
    @property
    def tidal(self) -> _F64: ...
    @property
    def momentum(self) -> _F64: ...
    @property
    def structural(self) -> _F64: ...
    @property
    def torque(self) -> _F64: ...
    @property
    def inertia(self) -> _F64: ...
    def __len__(self) -> int: ...

@final
class FlexibleModel:
    def __new__(cls, mu: float, body_arg: _FlexBody, *, primaries: list[bool] = ..., held: bool = False) -> FlexibleModel: ...

def flexible_body_check(body_arg: _FlexBody) -> FlexibleBodyConstants: ...
def flexible_propagate(
    model: FlexibleModel, orbit0: list[float], attitude0: tuple[float, float], q0: list[float], qdot0: list[float],
    t_span: tuple[float, float], *, options: IntegrationOptions, t_eval: _F64 | None
) -> FlexibleTrajectory: ...
def flexible_quasi_static(
    model: FlexibleModel, orbit0: list[float], attitude0: tuple[float, float], t_span: tuple[float, float], *,
    options: IntegrationOptions, t_eval: _F64 | None
) -> QuasiStaticTrajectory: ...
@final
class QuasiStaticPoint:
    @property
    def q(self) -> list[float]: ...
    @property
    def qdot(self) -> list[float]: ...
    @property
    def qddot(self) -> list[float]: ...
    @property
    def wzdot(self) -> float: ...
    @property
    def dtau(self) -> float: ...

def flexible_quasi_static_point(model: FlexibleModel, orbit: list[float], phi: float, wz: float) -> QuasiStaticPoint: ...
def flexible_energies(model: FlexibleModel, orbit: _F64, phi: _F64, wz: _F64, q: _F64, qdot: _F64) -> FlexibleEnergies: ...
def flexible_rates(
    model: FlexibleModel, orbit: list[float], phi: float, wz: float, q: list[float], qdot: list[float]
) -> tuple[float, list[float]]: ...

def planar_gravity_gradient(kz: float, s: _F64, c: _F64, phi: _F64) -> _F64: ...
def flat_plate_wzdot(eps: float, cs: float, cd: float, theta_sun0: float, t: _F64, phi: _F64) -> _F64: ...
def sun_angle(theta_sun0: float, t: _F64) -> _F64: ...
@final
class FlexiblePeriodicCorrection:
    @property
    def x(self) -> _F64: ...
    @property
    def residual(self) -> float: ...
    @property
    def iterations(self) -> int: ...
    @property
    def reason(self) -> str: ...
    @property
    def monodromy(self) -> _F64: ...

def flexible_correct_periodic(
    model: FlexibleModel, orbit: tuple[list[float], float], x0: list[float], turns: float, scale: list[float], *,
    options: IntegrationOptions, newton: NewtonOptions, threads: int | None = None,
) -> FlexiblePeriodicCorrection: ...

# --- 3-D attitude: equilibria and periodic motions (rust/py/src/attitude3d.rs) ---
__all__ += ["attitude_equilibrium", "attitude_correct_3d", "attitude_correct_3d_across", "LinearisedEquilibrium",
            "CorrectionBatch3D", "CorrectionAcross3D"]

@final
class LinearisedEquilibrium:
    @property
    def state(self) -> _F64: ...
    @property
    def matrix(self) -> _F64: ...
    @property
    def sigma(self) -> float: ...
    @property
    def residual(self) -> float: ...

@final
class CorrectionBatch3D:
    @property
    def q0(self) -> _F64: ...
    @property
    def w0(self) -> _F64: ...
    @property
    def residual(self) -> _F64: ...
    @property
    def residual_norm(self) -> _F64: ...
    @property
    def iterations(self) -> npt.NDArray[np.int64]: ...
    @property
    def reason(self) -> list[str]: ...
    @property
    def monodromy(self) -> _F64: ...
    def __len__(self) -> int: ...

def attitude_equilibrium(mu: float, inertia: list[float], point: int, q0: list[float]) -> LinearisedEquilibrium: ...
def attitude_correct_3d(
    mu: float, inertia: list[float], orbit0: list[float], t_final: float, cases: AttitudeCases3D, *, options: CorrectorOptions3D
) -> CorrectionBatch3D: ...

@final
class CorrectionAcross3D:
    @property
    def q0(self) -> _F64: ...
    @property
    def w0(self) -> _F64: ...
    @property
    def orbit0(self) -> _F64: ...
    @property
    def period(self) -> _F64: ...
    @property
    def residual(self) -> _F64: ...
    @property
    def residual_norm(self) -> _F64: ...
    @property
    def iterations(self) -> npt.NDArray[np.int64]: ...
    @property
    def reason(self) -> list[str]: ...
    @property
    def monodromy(self) -> _F64: ...
    @property
    def dparam(self) -> _F64: ...
    def __len__(self) -> int: ...

def attitude_correct_3d_across(
    mu: float, inertia: list[float], member0: list[float], period0: float, n_periods: int, cases: AttitudeCases3D, *,
    options: CorrectorOptions3D
) -> CorrectionAcross3D: ...

# --- 3-D attitude map engine (rust/py/src/map3d.rs) ---
__all__ += ["TidalTable", "Sweep3DResult", "map_sweep_3d", "MAP3D_ALIGN"]
#: Case alignment of the 3-D map engine: every SIMD level's lock-step group size divides it.
MAP3D_ALIGN: int

@final
class TidalTable:
    def __new__(cls, mu: float, state0: list[float], period: float, *, primaries: list[bool] = ..., tol: float = 1e-12) -> TidalTable: ...
    @property
    def period(self) -> float: ...
    @property
    def segments(self) -> int: ...
    @property
    def max_error(self) -> float: ...
    def tensor(self, t: _F64) -> _F64: ...

@final
class Sweep3DResult:
    @property
    def residual(self) -> _F64: ...
    @property
    def q_t(self) -> _F64: ...
    @property
    def w_t(self) -> _F64: ...
    @property
    def status(self) -> npt.NDArray[np.uint8]: ...
    @property
    def steps(self) -> npt.NDArray[np.uint32]: ...
    def __len__(self) -> int: ...

def map_sweep_3d(table: TidalTable, t_final: float, q0: _F64, w0: _F64, inertia: _F64, *, lanes: LaneOptions) -> Sweep3DResult: ...

__all__ += ["EphemerisCore", "GM_EARTH", "GM_MOON", "GM_SUN"]

GM_EARTH: float
GM_MOON: float
GM_SUN: float

@final
class EphemerisCore:
    def __new__(cls, segments: list[tuple[int, int, float, float, float, float, npt.NDArray[np.float64]]]) -> EphemerisCore: ...
    def span(self) -> tuple[float, float]: ...
    def state(self, target: int, center: int, t: float) -> npt.NDArray[np.float64]: ...
    def frame(self, t: float) -> dict[str, Any]: ...
    def synodic_to_ephemeris(self, t: float, mu: float, state: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def ephemeris_to_synodic(self, t: float, mu: float, state_km: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def propagate(
        self,
        state_km: npt.NDArray[np.float64],
        epoch: float,
        duration_s: float,
        stm: bool = False,
        t_eval: npt.NDArray[np.float64] | None = None,
        rtol: float = 1e-13,
        atol: float = 1e-9,
        gm: tuple[float, float, float] | None = None,
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64] | None]: ...
    def propagate_batch(
        self,
        states_km: npt.NDArray[np.float64],
        epochs: npt.NDArray[np.float64],
        durations_s: npt.NDArray[np.float64],
        stm: bool = False,
        integration: tuple[float, float] = ...,
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64] | None, dict[int, Exception]]: ...
    def transition(
        self,
        states_km: npt.NDArray[np.float64],
        epochs: npt.NDArray[np.float64],
        tol: tuple[float, float],
        scales: tuple[float, float],
        epoch_free: bool = False,
        max_iter: int = 30,
        integration: tuple[float, float] = ...,
        gm: tuple[float, float, float] | None = None,
    ) -> dict[str, Any]: ...

__all__ += ["EphemerisAttitudeModel", "eclipse_fraction", "R_SUN_KM", "R_EARTH_KM", "R_MOON_KM", "AU_KM"]

R_SUN_KM: float
R_EARTH_KM: float
R_MOON_KM: float
AU_KM: float

def eclipse_fraction(r: tuple[float, float, float] | Sequence[float], sun: Sequence[float], body: Sequence[float],
                     radius_km: float) -> float: ...
@final
class EphemerisAttitudeModel:
    def __new__(
        cls,
        ephemeris: EphemerisCore,
        inertia: tuple[float, float, float] | Sequence[float],
        gravity_gradient: tuple[bool, bool, bool] | Sequence[bool] = ...,
        facets: list[tuple[float, Sequence[float], Sequence[float], float, float, float]] | None = None,
        pressure: float = ...,
        eclipses: bool = True,
    ) -> EphemerisAttitudeModel: ...
    def propagate(
        self,
        state: npt.NDArray[np.float64],
        epoch: float,
        duration_s: float,
        stm: bool = False,
        t_eval: npt.NDArray[np.float64] | None = None,
        rtol: float = 1e-12,
        atol: float = 1e-15,
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64] | None]: ...
    def torque(self, epoch: float, state: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def place(
        self, epochs: npt.NDArray[np.float64], q: npt.NDArray[np.float64], w: npt.NDArray[np.float64], inverse: bool = False
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def legs(
        self,
        epochs: npt.NDArray[np.float64],
        orbits: npt.NDArray[np.float64],
        q: npt.NDArray[np.float64],
        w: npt.NDArray[np.float64],
        rtol: float = 1e-12,
        atol: float = 1e-15,
    ) -> dict[str, Any]: ...
    def correct(
        self,
        epochs: npt.NDArray[np.float64],
        orbits: npt.NDArray[np.float64],
        q: npt.NDArray[np.float64],
        w: npt.NDArray[np.float64],
        tol: float = 1e-9,
        max_iter: int = 30,
        tolerances: tuple[float, float] = ...,
    ) -> dict[str, Any]: ...
