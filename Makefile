# fepost: `make demo` runs the main job on the sample meshes, `make test` runs the tests.
# Both create their own virtual environment (.venv) and install what they need, saying
# what they do: the demo only the package and the GL libraries VTK renders with; the
# tests also the test, model and docs extras, CalculiX and Chromium. Missing Debian
# packages are listed first with every package apt will install or upgrade for them
# (a simulated `apt-get -s install`), and Chromium's side effect is said before it
# happens: it registers itself as the system's default web browser.

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip --disable-pip-version-check
OUT    ?= report
# One stamp per set of extras: `make demo` then `make test` in one clone installs the
# extras the tests need on top of the demo's install.
DEMO_STAMP := $(VENV)/.installed-demo
TEST_STAMP := $(VENV)/.installed-test
# Debian packages. GL: the libraries VTK's off-screen rendering loads (Figures 1-2).
GL_PACKAGES   := libgl1 libegl1 libosmesa6 libxrender1
# Tests only: CalculiX (the sample model's end-to-end test), Chromium (report screenshot).
TEST_PACKAGES := calculix-ccx chromium $(GL_PACKAGES)

.PHONY: demo test docs venv system-deps-demo system-deps-test lint bench clean

$(PY):
	@echo "== creating the virtual environment $(VENV) with $(PYTHON)"
	$(PYTHON) -m venv $(VENV)
	$(PIP) install --upgrade pip

$(DEMO_STAMP): pyproject.toml | $(PY)
	@echo "== installing fepost and its run-time dependencies from PyPI (a few minutes the first time)"
	$(PIP) install --progress-bar on -e .
	@touch $@

$(TEST_STAMP): pyproject.toml | $(PY)
	@echo "== installing fepost with the test, model and docs extras from PyPI"
	$(PIP) install --progress-bar on -e '.[test,model,docs]'
	@touch $@

venv: $(TEST_STAMP)

# Installs the Debian packages of $(1) that are missing (as root, or through sudo).
define apt_install
	@if ! command -v dpkg >/dev/null 2>&1; then \
	  echo "== not a Debian system: install $(1) (or your system's equivalents) yourself"; exit 0; \
	fi; \
	missing=""; for p in $(1); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -z "$$missing" ]; then echo "== system packages present: $(1)"; exit 0; fi; \
	if [ "$$(id -u)" = 0 ]; then SUDO=""; else SUDO="sudo"; fi; \
	$$SUDO apt-get update -q || exit 1; \
	echo "== missing system packages:$$missing; apt will install or upgrade (a simulated run, apt-get -s):"; \
	apt-get -s install --no-install-recommends $$missing | sed -n \
	  -e 's/^Inst \([^ ]*\) \[\([^]]*\)\] (\([^ ]*\).*/     \1 \2 -> \3 (upgrade)/p' \
	  -e 's/^Inst \([^ ]*\) (\([^ ]*\).*/     \1 \2 (new)/p'; \
	case " $$missing " in *" chromium "*) echo "== note: the chromium package registers itself as the system's default web browser (x-www-browser, gnome-www-browser; undo with update-alternatives --config x-www-browser)";; esac; \
	echo "== installing them"; \
	DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -q --no-install-recommends $$missing
endef

system-deps-demo:
	$(call apt_install,$(GL_PACKAGES))

system-deps-test:
	$(call apt_install,$(TEST_PACKAGES))

demo: $(DEMO_STAMP) system-deps-demo
	@echo "== fepost report on the sample aircraft tire at its rated load (meshes/aircraft/static_100, rolled map meshes/rig-aircraft/roll_free) -> $(OUT)/"
	$(VENV)/bin/fepost report --out $(OUT) --force
	@echo "== open $(OUT)/report.html"

# FEPOST_REQUIRE_DOCS: tests/test_docs.py fails (instead of skipping) without the docs
# tooling, so the strict docs build always runs here. Every test, in TEST_WORKERS pytest-xdist
# processes (one per core; pyproject.toml adds -q, --durations=15 and --dist loadfile).
# Compiled modules and pytest's rewritten test modules are cached under the venv
# (PYTHONPYCACHEPREFIX, even where PYTHONDONTWRITEBYTECODE is set): every worker and every
# command the tests run would otherwise compile them again.
TEST_WORKERS ?= auto
test: $(TEST_STAMP) system-deps-test
	@echo "== running the test suite on $(TEST_WORKERS) workers (includes the strict docs build)"
	env -u PYTHONDONTWRITEBYTECODE PYTHONPYCACHEPREFIX=$(abspath $(VENV))/pycache FEPOST_REQUIRE_DOCS=1 \
	  $(PY) -m pytest -n $(TEST_WORKERS); rc=$$?; if [ $$rc -eq 5 ]; then echo "no tests collected"; rc=0; fi; exit $$rc

# The documentation site (MkDocs, warnings are errors) -> site/
docs: $(TEST_STAMP)
	$(VENV)/bin/mkdocs build --strict --site-dir site

# ruff (rules and the reasons for each ignored one in pyproject.toml), the formatting, mypy
lint: $(TEST_STAMP)
	$(VENV)/bin/ruff check fepost tests scripts benchmarks docs
	$(VENV)/bin/ruff format --check fepost tests scripts benchmarks
	$(VENV)/bin/mypy fepost

bench: $(TEST_STAMP)
	for b in benchmarks/bench_*.py; do echo "== $$b"; $(PY) $$b || exit 1; done

clean:
	rm -rf $(VENV) $(OUT) site .pytest_cache
