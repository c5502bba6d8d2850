"""The Earth-Moon-Sun ephemeris model: JPL SPK files read with jplephem (spk), epochs with a time
scale (epochs), the Chebyshev segments evaluated in Rust, the Moon-centred ICRF point-mass
dynamics with the STM, and the instantaneous Earth-Moon frame (model)."""

from .model import Ephemeris, EphemerisBatch, EphemerisTrajectory, RotatingFrame, propagate_ephemeris, propagate_ephemeris_many, sun_phase

__all__ = ["Ephemeris", "EphemerisBatch", "EphemerisTrajectory", "RotatingFrame", "propagate_ephemeris", "propagate_ephemeris_many",
           "sun_phase"]
