"""The Earth-Moon-Sun ephemeris model: JPL SPK Chebyshev segments evaluated in Rust, the
Moon-centred ICRF point-mass dynamics with the STM, and the instantaneous Earth-Moon frame."""

from .model import Ephemeris, EphemerisTrajectory, RotatingFrame, propagate_ephemeris, sun_phase

__all__ = ["Ephemeris", "EphemerisTrajectory", "RotatingFrame", "propagate_ephemeris", "sun_phase"]
