"""librate's exceptions, defined in the Rust extension and re-exported here."""

from ._core import ConvergenceError, IntegrationError, LibrateError

__all__ = ["LibrateError", "IntegrationError", "ConvergenceError"]
