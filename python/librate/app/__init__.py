"""The application layer: studies (TOML or Python), the resumable map runner, result files and
the ``librate`` command line."""

from .results import open_result
from .runner import run_map
from .study import Study, StudyError

__all__ = ["Study", "StudyError", "run_map", "open_result"]
