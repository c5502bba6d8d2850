"""The application layer: studies (TOML or Python), the resumable map runner, result files and
the ``librate`` command line."""

__all__ = ["Study", "StudyError", "run_map", "open_result"]

#: Each name's module, imported on first use: a command that needs no study (``librate demo``,
#: ``dros``, ``info``, ``plot``) does not load the study schema (pydantic) or the map runner.
_WHERE = {"Study": "study", "StudyError": "study", "run_map": "runner", "open_result": "results"}


def __getattr__(name: str):
    if name in _WHERE:
        import importlib

        obj = getattr(importlib.import_module(f"{__name__}.{_WHERE[name]}"), name)
        globals()[name] = obj
        return obj
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
