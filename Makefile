# Two commands do all the set-up on a fresh Debian machine with Python >= 3.11:
#   make demo   -- install, then the complete analysis of the 1-4 system with its deployment
#                  (tmfem report; out/1-4/index.md links every file)
#   make test   -- install, then run the test suite
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
OUT    ?= out

.PHONY: demo test install clean

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
	@touch $@

demo: $(STAMP)
	$(BIN)/tmfem report --preset 1-4 --out $(OUT)/1-4

test: $(STAMP)
	$(BIN)/python -m pytest -q

clean:
	rm -rf $(VENV) $(OUT)
