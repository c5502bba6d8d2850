"""The progress style of the command line and the app layer (maps, their solutions, solution
tables, figures): the one of :mod:`librate._progress` (a tqdm bar on stderr, drawn only when
stderr is a terminal, and never with ``--quiet``)."""

from .._progress import bar, reporter, shown

__all__ = ["bar", "reporter", "shown"]
