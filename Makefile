# Set-up, main job and tests. `make demo` and `make test` work on a fresh
# machine: they create .venv with a Python >= 3.12 and install the package.
VENV    ?= .venv
PYTHON  ?= $(shell scripts/find-python)
EXTRAS  ?= dolfinx,mesh,viz,test
BIN     := $(VENV)/bin
MPIEXEC ?= $(shell [ -x $(BIN)/mpiexec ] && echo $(BIN)/mpiexec || echo mpiexec)
OUT     ?= results

.PHONY: demo test test-serial test-mpi soak venv meshes lint clean paper-tables paper-ex1-geometry \
        cattaneo-mindlin tradeoff stability benchmarks docs

venv: $(VENV)/.installed

$(VENV)/.installed: pyproject.toml
	@test -n "$(PYTHON)" || { echo "error: no Python >= 3.12 found (see above)"; exit 1; }
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[$(EXTRAS)]"
	@touch $@

# The main job: the paper's Example 2 analog with GNRM for r = 1 ... 10000.
demo: venv
	$(BIN)/python demos/paper_example2.py --out $(OUT)/paper-ex2

test: lint test-serial test-mpi

test-serial: venv
	$(BIN)/python -m pytest -q

# Tests marked `mpi` again on two processes.
test-mpi: venv
	$(MPIEXEC) -n 2 $(BIN)/python -m pytest -q -m mpi -p no:cacheprovider

# The property-based soak with many random scenes (tests/test_soak.py runs a
# few derandomized ones in `make test`); SOAK_EXAMPLES sets how many.
SOAK_EXAMPLES ?= 200
soak: venv
	HYPOTHESIS_PROFILE=soak SOAK_EXAMPLES=$(SOAK_EXAMPLES) $(BIN)/python -m pytest -q \
	    --hypothesis-show-statistics tests/test_soak.py

# .msh files from every meshes/*.geo (physical groups kept).
meshes: venv
	$(BIN)/fenics-contact mesh

# The laboratory (benchmarks/: research, validation, robustness, performance).
# The paper's Tables 1 and 2 beside ours (Example 1 also beside the wedge analog).
paper-tables: venv
	$(BIN)/python benchmarks/research/study.py paper-ex1 --beside paper-ex1-wedge \
	    --out $(OUT)/paper-ex1
	$(BIN)/python benchmarks/research/study.py paper-ex2 --out $(OUT)/paper-ex2-study

# The search that reconstructs Example 1's geometry from the paper's numbers (~2 min).
paper-ex1-geometry: venv
	$(BIN)/python benchmarks/research/paper_ex1_geometry.py --figure docs/images/paper_ex1_geometry.png

# Cattaneo-Mindlin with two identical cylinders on three meshes, and the README picture (~1-2 min).
cattaneo-mindlin: venv
	$(BIN)/python benchmarks/validation/cattaneo_mindlin.py --out $(OUT)/bench \
	    --figure docs/images/cattaneo_mindlin.png

# Speed against accuracy: Hertz, the bar and the sliding block, methods x r x 3 meshes.
tradeoff: venv
	$(BIN)/python benchmarks/research/tradeoff.py --scene all --out $(OUT)/tradeoff

# Every method on the grid of extreme cases.
stability: venv
	$(BIN)/python benchmarks/robustness/stability_grid.py --out $(OUT)/stability

# The performance benchmarks (minutes to hours; --quick stops at 1e5 DOFs).
benchmarks: venv
	$(BIN)/python benchmarks/run_all.py --quick

# The documentation site into docs/_build/html (Sphinx; warnings are errors). The
# venv gains the `docs` extra; the demos run as notebooks at their CI size.
docs: $(VENV)/.installed-docs
	rm -rf docs/_generated/api  # pages of modules that no longer exist would fail the build
	$(BIN)/sphinx-build -b html -W --keep-going docs docs/_build/html
	@echo "The site: docs/_build/html/index.html"

$(VENV)/.installed-docs: $(VENV)/.installed pyproject.toml
	$(BIN)/python -m pip install --quiet -e ".[docs]"
	@touch $@

lint: venv
	$(BIN)/ruff check fenics_contact tests demos benchmarks

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache docs/_build docs/_generated
