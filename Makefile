# Developer targets: the same checks as .ci/run, one at a time.
#   make dev      build the extension in the dev profile into the active environment (fast to rebuild)
#   make lint     clippy, ruff, the import layers, the structure of the stubs
#   make test     the README's test command on the installed package (Rust, then pytest)
#   make fast     pytest without the slow validations
#   make docs     the documentation site, warnings as errors
#   make ci       everything CI runs (.ci/run)
PYTHON ?= python

.PHONY: dev lint test fast docs ci

dev:
	maturin develop --profile dev

lint:
	cargo clippy --workspace --all-targets -- -D warnings
	ruff check python tests examples bench
	lint-imports
	$(PYTHON) -m mypy.stubtest librate._core

test:
	cargo test
	$(PYTHON) -m pytest

fast:
	$(PYTHON) -m pytest -m "not slow"

docs:
	mkdocs build --strict

ci:
	bash .ci/run
