//! The Earth-Moon-Sun ephemeris model: JPL SPK type-2 Chebyshev segments evaluated in Rust
//! ([`chebyshev`]), the spacecraft dynamics under Earth, Moon and Sun point masses in
//! Moon-centred ICRF axes with the exact STM ([`dynamics`]), and the instantaneous Earth-Moon
//! rotating frame with the maps between CR3BP synodic and ephemeris states ([`frame`]), the
//! transition of orbits to the model by multiple shooting ([`transition`]), and the rigid-body
//! attitude along an ephemeris orbit ([`attitude`], eclipses in [`eclipse`]) with its correction
//! by multiple shooting ([`attitude_shooting`]).
//! Units: km, km/s, TDB seconds past J2000.

pub mod attitude;
pub mod attitude_shooting;
pub mod chebyshev;
pub mod dynamics;
pub mod eclipse;
pub mod frame;
pub mod transition;

pub use chebyshev::{Ephemeris, Segment, EARTH, EMB, MOON, SSB, SUN};
pub use dynamics::{propagate_ephemeris, propagate_ephemeris_batch, EphemerisDynamics, EphemerisTrajectory, GM_EARTH, GM_MOON, GM_SUN};
pub use frame::{ephemeris_to_synodic, synodic_to_ephemeris, RotatingFrame};
pub use transition::{transition, Transition, TransitionSettings};
