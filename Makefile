# Two commands do all the set-up on a fresh Debian machine with Python >= 3.11:
#   make demo   -- install, then the complete analysis of the 1-4 system with its deployment
#                  (tmfem report; out/1-4/report.html shows it, index.md links every file)
#   make test   -- install, then run the fast test suite (every feature, a few minutes)
# and beside them:
#   make test-full     -- every test, the studies at full scale (about 40 min)
#   make test-studies  -- only the studies and the longest end-to-end runs (the studies at the
#                         size given by TMFEM_SLOW_SCALE; CI: reduced)
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
OUT    ?= out

.PHONY: demo test test-full test-studies install clean

install: $(STAMP)

# System libraries needed by the gmsh and VTK wheels (OpenGL, X client libs for
# off-screen rendering); installed only when missing.
$(VENV)/.syslibs:
	@bash scripts/install_system_libs.sh
	@mkdir -p $(VENV) && touch $@

$(STAMP): pyproject.toml $(VENV)/.syslibs
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	@bash scripts/install_petsc.sh $(VENV)
	@bash scripts/install_browser.sh
	@$(BIN)/python -m compileall -q tmfem
	@touch $@

demo: $(STAMP)
	$(BIN)/tmfem report --preset 1-4 --out $(OUT)/1-4
	@echo "tmfem: the report as one web page: $(abspath $(OUT))/1-4/report.html"

# two workers: the suite is CPU-bound and the machines have two cores. Bytecode caches are
# written even where PYTHONDONTWRITEBYTECODE is set: without them every worker rewrites the
# test modules' asserts and every command a test starts (the CLI, each MPI rank) compiles
# the package anew (the editable install is compiled at install time; cached files are in
# __pycache__/, which git ignores). The tests of one xdist_group run on one worker (those of
# the shared report: no worker idles while the other builds it).
PYTEST := PYTHONDONTWRITEBYTECODE= $(BIN)/python -m pytest -q -n 2 --dist loadgroup

test: $(STAMP)
	$(PYTEST) -m "not slow"

test-full: $(STAMP)
	$(PYTEST)

test-studies: $(STAMP)
	$(PYTEST) -m slow

clean:
	rm -rf $(VENV) $(OUT)
