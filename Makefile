# seawatch — two entry points for a fresh machine: `make demo` and `make test`.
# Both create .venv if missing and install what they need from the package registries.

PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
OUT    ?= out/demo

.PHONY: demo test lint format bench results clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

# TrackEval (CLEAR-MOT, IDF1, HOTA) is installed without its declared dependencies:
# they pull in opencv-python (the GUI build, which clashes with opencv-python-headless
# over the cv2 module) and pycocotools, neither needed by the metric classes we use
# (../shared/spec/DEPENDENCIES.md).
TRACKEVAL := trackeval==1.3.0 tabulate

# Stamps: reinstall only when pyproject.toml changes.
$(VENV)/.installed-base: pyproject.toml | $(BIN)/python
	$(BIN)/pip install --quiet -e .
	$(BIN)/pip install --quiet --no-deps $(TRACKEVAL)
	touch $@

$(VENV)/.installed-test: pyproject.toml | $(BIN)/python
	$(BIN)/pip install --quiet -e '.[test]'
	$(BIN)/pip install --quiet --no-deps $(TRACKEVAL)
	touch $@ $(VENV)/.installed-base

demo: $(VENV)/.installed-base
	$(BIN)/seawatch demo --out $(OUT)

test: $(VENV)/.installed-test
	$(BIN)/ruff check src tests examples
	$(BIN)/ruff format --check src tests examples
	$(BIN)/python -m pytest -q -n auto --dist loadfile

lint: $(VENV)/.installed-test
	$(BIN)/ruff check src tests examples
	$(BIN)/ruff format --check src tests examples

format: $(VENV)/.installed-test
	$(BIN)/ruff format src tests examples
	$(BIN)/ruff check --fix src tests examples

bench: $(VENV)/.installed-test
	$(BIN)/seawatch bench filters

clean:
	rm -rf $(VENV) out .pytest_cache .ruff_cache .hypothesis
