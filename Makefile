# fkopt -- common tasks. `make install` once, then `make reproduce` / `make test`.
# Every target runs the project's venv (.venv, made by `make install`) when it exists, so a bare
# `fkopt` on the PATH is never needed; PYTHON=... picks another interpreter.
PYTHON ?= $(if $(wildcard .venv/bin/python),.venv/bin/python,python3)
FKOPT = $(PYTHON) -m fkopt.cli

.PHONY: install install-peers test test-fast reproduce reproduce-peers report check bench bench-suite clean constraints

# constraints.txt pins every dependency at the version the stored results were made with.
install:
	test -x .venv/bin/python || python3 -m venv .venv
	.venv/bin/python -m pip install -e ".[test]" -c constraints.txt

# Move the pins on purpose: upgrade .venv (e.g. pip install -U -e ".[test]"), regenerate results/
# (make reproduce) with it, then record what it holds here, all in one commit.
constraints:
	{ echo "# Every library in the venv that made results/ (make constraints); pip install -c constraints.txt"; \
	  $(PYTHON) -m pip freeze --exclude-editable | grep -v -i '^fkopt'; } > constraints.txt

# The optional libraries of the peer configs (pymoo, NiaPy); scipy's adapters need nothing.
install-peers:
	$(PYTHON) -m pip install -e ".[peers]"

test:
	$(PYTHON) -m pytest

# Rerun every experiment under configs/ and rewrite results/ (REPORT.md, TIMING.md, index.csv).
reproduce:
	$(FKOPT) reproduce --configs configs --out results

# The peer configs (peers/*.yaml: fkopt beside NiaPy, pymoo and scipy at equal evaluations).
# Slow (NiaPy evaluates one point per call) and outside `make reproduce`; needs install-peers.
reproduce-peers:
	$(FKOPT) reproduce --configs peers --out results/peers --compare-with results/peers
	$(PYTHON) -m fkopt.tools.peers results/peers

# kinbench (docs/kinbench.md): v1, v2 and v3's evaluations track in full (v3: exact and lm on every
# problem, set and pose, the others on the subsets its YAML documents), v3's per-robot board on the
# clock (one process: its times are ratios measured side by side), v3's all-solutions and paths
# tracks, the quick tiers (which CI's check reruns: v1, v2, v3, v3's board and its solutions) and
# the libraries subset into results/kinbench/, then
# the report (~25 min on 2 cores before v3 in full, which adds ~12 min: measured 11 min 49 s, docs/kinbench.md). Not part of `make reproduce`.
bench-suite:
	$(FKOPT) report results --snapshot-to .bench-suite-before.json
	for s in kinbench kinbench-v2 kinbench-v2-libraries kinbench-v3; do \
	  $(FKOPT) suite configs/suites/$$s.yaml --out results --force --jobs 2 -q || exit 1; done
	$(FKOPT) suite configs/suites/kinbench-v3-robots.yaml --out results --force -q
	$(FKOPT) suite configs/suites/kinbench-v3-solutions.yaml --out results --force -q
	for s in kinbench kinbench-v2 kinbench-v3 kinbench-v3-robots kinbench-v3-solutions; do \
	  $(FKOPT) suite configs/suites/$$s.yaml --out results --force --quick -q || exit 1; done
	$(FKOPT) report results --changes-since .bench-suite-before.json   # CHANGES.md: what the suites moved
	rm -f .bench-suite-before.json

# Regenerate the report from stored results without rerunning.
report:
	$(FKOPT) report results

# Rerun every stored experiment (CI reruns the `check: ci` subset through the tests).
check:
	$(FKOPT) check results --subset all

bench:
	$(FKOPT) bench --out bench

clean:
	rm -rf build dist *.egg-info .pytest_cache examples/plugin/build examples/plugin/*.egg-info

# The fast tier: everything but slow, stored-results, outside-tool and browser tests (markers in
# tests/conftest.py). Run it after every change; `make test` (the full suite) is what CI runs.
test-fast:
	$(PYTHON) -m pytest -q -n 2 -m "not slow and not stored and not external and not browser"
