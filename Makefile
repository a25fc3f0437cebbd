# fepost: `make demo` runs the main job on the sample meshes, `make test` runs the tests.
# Both create their own virtual environment (.venv) and install what they need.

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
APT_PACKAGES := calculix-ccx chromium libgl1 libegl1 libosmesa6 libxrender1
OUT    ?= report

.PHONY: demo test venv system-deps lint bench clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test,model]'
	touch $(STAMP)

venv: $(STAMP)

# System packages: CalculiX (sample model and its end-to-end test), Chromium (report
# screenshot test) and the GL libraries VTK's off-screen rendering loads.
system-deps:
	@missing=""; for p in $(APT_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing system packages:$$missing"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=""; else SUDO="sudo"; fi; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$missing >/dev/null; \
	fi

demo: $(STAMP) system-deps
	$(VENV)/bin/fepost report --out $(OUT) --force
	@echo "open $(OUT)/report.html"

test: $(STAMP) system-deps
	$(PY) -m pytest; rc=$$?; if [ $$rc -eq 5 ]; then echo "no tests collected"; rc=0; fi; exit $$rc

lint: $(STAMP)
	$(VENV)/bin/ruff check fepost tests scripts benchmarks
	$(VENV)/bin/mypy fepost

bench: $(STAMP)
	for b in benchmarks/bench_*.py; do echo "== $$b"; $(PY) $$b || exit 1; done

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache
