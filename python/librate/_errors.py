"""librate's exceptions, defined in the Rust extension and re-exported here."""

from ._core import CollisionError, ConvergenceError, IntegrationError, LibrateError

__all__ = ["LibrateError", "IntegrationError", "CollisionError", "ConvergenceError"]
