# Two commands do all the set-up on a fresh machine (Python 3.11 + pip):
#   make demo   - the model problem: landscape + identification (outputs in out/)
#   make test   - the test suite
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

TEX_PACKAGES := latexmk texlive-latex-recommended texlive-latex-extra texlive-fonts-recommended \
	lmodern poppler-utils

.PHONY: install demo test test-fast bench lint clean tex

install: $(STAMP)

$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e ".[dev]"
	$(BIN)/python -m discovery.warm
	touch $(STAMP)

demo: install
	$(BIN)/vidi simulate --scenario paper --periods 20 --fs 20000 --noise 0 --out out/model_problem.csv
	$(BIN)/vidi landscape --scenario paper --grid 41x41 --out out/landscape
	$(BIN)/vidi identify --scenario paper --data out/model_problem.csv --criterion I2 \
		--method least-squares --start "1.5e8*z + 0.9e7*zd" --landscape out/landscape \
		--out out/identify
	@echo "demo outputs: out/landscape/ (landscape.png/.pdf, landscape.csv, summary.json)," \
		"out/identify/ (identification.png/.pdf, iterations.csv, summary.json)"

# TeX Live for `vidi report` PDFs (optional: without it the reports are .tex files)
tex:
	@if command -v latexmk >/dev/null && command -v pdftotext >/dev/null; then \
		echo "TeX Live is installed"; \
	else \
		SUDO=$$([ "$$(id -u)" = 0 ] || echo sudo); \
		$$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install \
			-y -qq --no-install-recommends $(TEX_PACKAGES); \
	fi

test: install
	$(BIN)/python -m pytest -q

test-fast: install
	$(BIN)/python -m pytest -q -m "not slow"

bench: install
	cd bench && ../$(BIN)/python run.py

lint: install
	$(BIN)/ruff check discovery constraints reports tests bench

clean:
	rm -rf out bench/_work .pytest_cache
