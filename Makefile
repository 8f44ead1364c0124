# fkopt -- common tasks. `make install` once, then `make reproduce` / `make test`.
PYTHON ?= python3

.PHONY: install test reproduce report check bench clean

install:
	$(PYTHON) -m pip install -e ".[test]"

test:
	$(PYTHON) -m pytest

# Rerun every experiment under configs/ and rewrite results/ (REPORT.md, TIMING.md, index.csv).
reproduce:
	fkopt reproduce --configs configs --out results

# Regenerate the report from stored results without rerunning.
report:
	fkopt report results

# Rerun every stored experiment (CI reruns the `check: ci` subset through the tests).
check:
	fkopt check results --subset all

bench:
	fkopt bench --out bench

clean:
	rm -rf build dist *.egg-info .pytest_cache
