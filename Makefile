# flexgear: make (quick matrix + report), make test, make meshes, make matrix (full 0.6 s), make report
PY ?= python3
VARIANTS := $(sort $(wildcard model_variants/model*.toml))
QUICK_VARIANTS := $(sort $(wildcard model_variants/quick/model*.toml))
RESULTS ?= results

.PHONY: quick install test lint meshes matrix report lpm bench clean

quick: install
	$(PY) -m flexgear.cli meshes --level coarse
	$(PY) -m flexgear.cli matrix $(QUICK_VARIANTS) --out $(RESULTS)/quick --reference model7
	$(PY) -m flexgear.cli lpm model_variants/quick/model1.toml --out $(RESULTS)/quick
	$(PY) -m flexgear.cli sweep examples/sweeps/face_width.toml --out $(RESULTS)/quick/sweep_face_width
	$(PY) -m flexgear.cli report $(RESULTS)/quick --output reports/screening_report.pdf

install:
	$(PY) -m pip install --quiet --disable-pip-version-check -e ".[test]"

lint:
	$(PY) -m ruff check flexgear tests benchmarks examples
	$(PY) -c "from importlinter.cli import lint_imports; raise SystemExit(lint_imports(no_cache=True, no_logo=True))"

test: lint
	$(PY) -m pytest -q

meshes:
	$(PY) -m flexgear.cli meshes --level coarse
	$(PY) -m flexgear.cli meshes --level default --no-reduce

matrix:
	$(PY) -m flexgear.cli matrix $(VARIANTS) --out $(RESULTS)/full --reference model7
	$(PY) -m flexgear.cli lpm model_variants/gearbox.toml --out $(RESULTS)/full

report:
	$(PY) -m flexgear.cli report $(RESULTS)/full --output reports/screening_report.pdf

lpm:
	$(PY) -m flexgear.cli lpm model_variants/gearbox.toml --out $(RESULTS)/full

bench:
	$(PY) benchmarks/bench_rigid.py --repeat 3

clean:
	rm -rf $(RESULTS) reports/*.pdf
