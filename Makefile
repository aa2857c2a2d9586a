# flexgear: make (both laws' quick matrices in one pool + report), make test, make meshes, make matrix (full 0.6 s, both mesh laws), make report
#
# Environment: inside an active virtual environment ($VIRTUAL_ENV) make uses it; otherwise it creates
# .venv with the first Python 3.11-3.13 it finds (PYTHON=/path/to/python3.x chooses one) and installs
# the project there (pip install -e ".[test]", again only when pyproject.toml changes). Nothing is
# installed system-wide, so a Python that refuses system-wide installs (Debian's) works too.
ifdef VIRTUAL_ENV
VENV ?= $(VIRTUAL_ENV)
else
VENV ?= .venv
endif
PY := $(VENV)/bin/python
STAMP := $(VENV)/.flexgear-installed
PYTHON_CANDIDATES := $(PYTHON) python3 python3.13 python3.12 python3.11 /usr/bin/python3
VARIANTS := $(sort $(wildcard model_variants/model*.toml))
ISO_VARIANTS := $(sort $(wildcard model_variants/iso6336/model*.toml))
QUICK_VARIANTS := $(sort $(wildcard model_variants/quick/model*.toml))
QUICK_ISO_VARIANTS := $(sort $(wildcard model_variants/quick_iso6336/model*.toml))
QUICK_MM_VARIANTS := $(sort $(wildcard model_variants/quick_mm_reading/model*.toml))
RESULTS ?= results
# input speeds [rpm] of the frequency-domain screening over the operating range (±50 % of Table 5's 6000 rpm in
# steps of 100 rpm; the speed band of each selected variant per purpose, flexgear.study.speed_screening)
SPEEDS_RPM ?= 3000:9000:100
# pytest-xdist worker processes of `make test` (the machine's 2 cores; `make test TEST_WORKERS=auto` for all)
TEST_WORKERS ?= 2

.PHONY: quick install venv test test-heavy lint meshes matrix readings report lpm bench api-docs clean distclean

quick: install
	$(PY) -m flexgear.cli matrix $(QUICK_VARIANTS) $(QUICK_ISO_VARIANTS) --out '$(RESULTS)/{folder}' --reference model7 \
		--speeds-rpm $(SPEEDS_RPM)
	$(PY) -m flexgear.cli lpm model_variants/quick/model1.toml --out $(RESULTS)/quick
	$(PY) -m flexgear.cli sweep examples/sweeps/face_width.toml --out $(RESULTS)/quick/sweep_face_width
	$(PY) -m flexgear.cli report $(RESULTS)/quick --output reports/screening_report.pdf --westgard-png docs/img/westgard.png \
		--also $(RESULTS)/quick_iso6336 $(RESULTS)/full $(RESULTS)/full_iso6336 $(RESULTS)/quick_mm_reading

install: $(STAMP)

$(STAMP): pyproject.toml
	@if [ ! -x "$(PY)" ]; then .ci/make-venv "$(VENV)" $(PYTHON_CANDIDATES); fi
	@echo "installing flexgear and its dependencies into $(VENV) (pip install -e .[test])"
	$(PY) -m pip install --quiet --disable-pip-version-check --no-compile -e ".[test]"
	@touch $(STAMP)

venv: install

lint: install
	$(PY) -m ruff check flexgear tests benchmarks examples
	$(PY) -c "from importlinter.cli import lint_imports; raise SystemExit(lint_imports(no_cache=True, no_logo=True))"

test: lint
	$(PY) -m pytest -q -n $(TEST_WORKERS) --dist loadgroup --prebuild --durations=25

test-heavy: install
	$(PY) -m pytest -q -m heavy

meshes: install
	$(PY) -m flexgear.cli meshes --level coarse
	$(PY) -m flexgear.cli meshes --level default --no-reduce

matrix: install
	$(PY) -m flexgear.cli matrix $(VARIANTS) --out $(RESULTS)/full --reference model7 --t-end settled \
		--speeds-rpm $(SPEEDS_RPM)
	$(PY) -m flexgear.cli matrix $(ISO_VARIANTS) --out $(RESULTS)/full_iso6336 --reference model7 --t-end settled \
		--speeds-rpm $(SPEEDS_RPM)
	$(PY) -m flexgear.cli lpm model_variants/gearbox.toml --out $(RESULTS)/full --t-end settled

# the study's contact stiffness read as N/mm^1.5 (ADAMS models in mm): the quick matrix and the lumped model;
# `make` then sets its tables and verdicts beside the N/m^1.5 reading on the report's sensitivity pages
readings: install
	$(PY) -m flexgear.cli matrix $(QUICK_MM_VARIANTS) --out $(RESULTS)/quick_mm_reading --reference model7
	$(PY) -m flexgear.cli lpm model_variants/quick_mm_reading/model1.toml --out $(RESULTS)/quick_mm_reading

report: install
	$(PY) -m flexgear.cli report $(RESULTS)/full --output reports/full_screening_report.pdf --also $(RESULTS)/quick \
		$(RESULTS)/quick_iso6336 $(RESULTS)/full_iso6336
	$(PY) -m flexgear.cli report $(RESULTS)/full_iso6336 --output reports/full_iso6336_screening_report.pdf \
		--also $(RESULTS)/quick_iso6336 $(RESULTS)/full $(RESULTS)/quick

lpm: install
	$(PY) -m flexgear.cli lpm model_variants/gearbox.toml --out $(RESULTS)/full

bench: install
	$(PY) benchmarks/bench_rigid.py --repeat 3

# docs/api.md from the docstrings of flexgear's public names (tests/test_api.py checks it is current)
api-docs: install
	$(PY) docs/gen_api.py

clean:
	rm -rf $(RESULTS) reports/*.pdf

distclean: clean
	rm -rf .venv
