# fepost: `make demo` runs the main job on the sample meshes, `make test` runs the tests.
# Both create their own virtual environment (.venv) and install what they need, saying
# what they do: fepost from this clone and its Python dependencies from PyPI; the demo
# needs the Debian packages in GL_PACKAGES (the GL libraries VTK renders with), the tests
# also CalculiX and Chromium (TEST_PACKAGES).
#
# System packages (Debian names; `make system-packages` lists them):
#   APT=yes (default; upgrade under CI=true)  install the missing ones with apt, listing first every package apt
#                      would install (a simulated `apt-get -s install`); apt never upgrades an
#                      installed package here: when it would (Mesa libraries, say), make stops,
#                      names them and leaves the choice to you (APT=upgrade lets apt do it);
#   APT=no             install nothing: install them yourself (or not) and run the rest; a
#                      missing one is named, and what needs it fails or skips with a reason.
#   CHROMIUM=no        the tests without Chromium (the report screenshot test then skips).
#                      With Chromium, the web-browser choice it takes over on installing
#                      (x-www-browser, gnome-www-browser) is given back as it was.

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip --disable-pip-version-check
OUT    ?= report
# CI (CI=true, a machine made for the run) lets apt upgrade what it needs to; a person's
# machine is never upgraded without APT=upgrade.
APT      ?= $(if $(CI),upgrade,yes)
CHROMIUM ?= yes
# One stamp per set of extras: `make demo` then `make test` in one clone installs the
# extras the tests need on top of the demo's install.
DEMO_STAMP := $(VENV)/.installed-demo
TEST_STAMP := $(VENV)/.installed-test
# Debian packages. GL: the libraries VTK's off-screen rendering loads (Figures 1-2).
GL_PACKAGES   := libgl1 libegl1 libosmesa6 libxrender1
# Tests only: CalculiX (the sample model's end-to-end test), Chromium (report screenshot).
TEST_PACKAGES := calculix-ccx $(if $(filter no,$(CHROMIUM)),,chromium) $(GL_PACKAGES)

.PHONY: demo test docs venv system-deps-demo system-deps-test system-packages lint bench clean

$(PY):
	@echo "== creating the virtual environment $(VENV) with $(PYTHON)"
	$(PYTHON) -m venv $(VENV)
	$(PIP) install --upgrade pip

$(DEMO_STAMP): pyproject.toml | $(PY)
	@echo "== installing fepost from this clone (editable) and its run-time dependencies from PyPI (a few minutes the first time)"
	$(PIP) install --progress-bar on -e .
	@touch $@

$(TEST_STAMP): pyproject.toml | $(PY)
	@echo "== installing fepost from this clone with the test, model and docs extras (dependencies from PyPI)"
	$(PIP) install --progress-bar on -e '.[test,model,docs]'
	@touch $@

venv: $(TEST_STAMP)

# Installs the Debian packages of $(1) that are missing (as root, or through sudo); see APT
# and CHROMIUM above. Never upgrades an installed package unless APT=upgrade.
define apt_install
	@echo "== system packages needed ($(2)): $(1)"; \
	if ! command -v dpkg >/dev/null 2>&1; then \
	  echo "== not a Debian system: install $(1) (or your system's equivalents) yourself"; exit 0; \
	fi; \
	missing=""; for p in $(1); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -z "$$missing" ]; then echo "== all present"; exit 0; fi; \
	if [ "$(APT)" = no ]; then \
	  echo "== APT=no: not installing the missing$$missing; install them yourself (what needs them fails or skips, naming them)"; exit 0; \
	fi; \
	if [ "$$(id -u)" = 0 ]; then SUDO=""; else SUDO="sudo"; fi; \
	$$SUDO apt-get update -q || exit 1; \
	sim=$$(apt-get -s install --no-install-recommends $$missing) || { echo "$$sim" | tail -5; exit 1; }; \
	echo "== missing system packages:$$missing; apt would install (a simulated run, apt-get -s):"; \
	echo "$$sim" | sed -n \
	  -e 's/^Inst \([^ ]*\) \[\([^]]*\)\] (\([^ ]*\).*/     \1 \2 -> \3 (UPGRADE of an installed package)/p' \
	  -e 's/^Inst \([^ ]*\) (\([^ ]*\).*/     \1 \2 (new)/p'; \
	if echo "$$sim" | grep -q '^Inst [^ ]* \['; then \
	  if [ "$(APT)" != upgrade ]; then \
	    echo "== stopped: that would upgrade installed packages (marked UPGRADE). Install$$missing yourself,"; \
	    echo "   or let apt upgrade them: make $@ APT=upgrade; or go on without them: make $@ APT=no"; \
	    exit 1; \
	  fi; \
	  echo "== APT=upgrade: apt upgrades the packages marked UPGRADE"; \
	fi; \
	before_x=$$(update-alternatives --query x-www-browser 2>/dev/null | sed -n 's/^Value: //p'); \
	before_g=$$(update-alternatives --query gnome-www-browser 2>/dev/null | sed -n 's/^Value: //p'); \
	echo "== installing them"; \
	DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -q --no-install-recommends --no-upgrade $$missing || exit 1; \
	for pair in "x-www-browser:$$before_x" "gnome-www-browser:$$before_g"; do \
	  name=$${pair%%:*}; before=$${pair#*:}; \
	  now=$$(update-alternatives --query $$name 2>/dev/null | sed -n 's/^Value: //p'); \
	  if [ "$$now" = "$$before" ] || [ -z "$$now" ]; then continue; fi; \
	  if [ -n "$$before" ]; then $$SUDO update-alternatives --set $$name "$$before" >/dev/null; \
	  else $$SUDO update-alternatives --remove $$name "$$now" >/dev/null; fi; \
	  echo "== $$name given back as it was ($${before:-none}; the installed package had made it $$now)"; \
	done
endef

system-packages:
	@echo "demo: $(GL_PACKAGES)"
	@echo "test: $(TEST_PACKAGES)"

system-deps-demo:
	$(call apt_install,$(GL_PACKAGES),make demo)

system-deps-test:
	$(call apt_install,$(TEST_PACKAGES),make test)

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
