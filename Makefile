# Two commands do all the set-up on a fresh machine (Python 3.11 + pip):
#   make demo   - a hidden effect found: verify, fit, explain, reports (outputs in out/demo)
#   make test   - the test suite
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

# The BLAS kernels: OpenBLAS picks them by the CPU, and they round sums in different orders,
# enough for a record of a long transient from rest to settle on another orbit.  The stored
# survey runs and the tests of named survey draws use the SkylakeX kernels, which every CPU
# with AVX-512 runs: pinned here for every target (a value you set is kept; tests/kernels.py)
ifeq ($(shell grep -qsw avx512f /proc/cpuinfo && echo y),y)
export OPENBLAS_CORETYPE ?= SkylakeX
endif

TEX_PACKAGES := latexmk texlive-latex-recommended texlive-latex-extra texlive-fonts-recommended \
	lmodern poppler-utils

.PHONY: install demo study test test-slow test-all bench bench-study bench-corpus lint clean tex docs tables surveys gallery readme

install: $(STAMP)

# compileall: the modules' bytecode written once; where PYTHONDONTWRITEBYTECODE is set (many
# containers set it) every command would otherwise compile its ~130 modules again (0.3 s)
$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e ".[dev]"
	$(BIN)/python -m compileall -q discovery reports constraints
	$(BIN)/python -m discovery.warm
	touch $(STAMP)

# The demo: a machine whose contact also damps while unloading (the hidden effect, outside
# the paper's condition (5)), recorded at two drive amplitudes by the independent scipy path
DEMO := out/demo
DEMO_LAW := 2.06e8*z + 4e6*zd
DEMO_TRUE := $(DEMO_LAW); unloading: 4e6*zd

demo: install
	@mkdir -p $(DEMO)
	@printf 'name = "grid-high"\n[machine]\nm1 = 1.0e4\nm2 = 1.0e4\nk1 = 2.75e7\nc1 = 1.0e5\nA = 5.0e5\nfrequency = 25.0\n[law]\ntext = "$(DEMO_LAW)"\n' > $(DEMO)/high.toml
	@sed 's/grid-high/grid-low/; s/A = 5.0e5/A = 3.5e5/' $(DEMO)/high.toml > $(DEMO)/low.toml
	@echo "== 1. records of the machine at two drive amplitudes (scipy path, from rest, 1 % noise)"
	$(BIN)/vidi simulate --scenario $(DEMO)/high.toml --law "$(DEMO_TRUE)" --from-rest \
		--integrator scipy --periods 30 --noise 0.01 --seed 1 --out $(DEMO)/high.csv
	$(BIN)/vidi simulate --scenario $(DEMO)/low.toml --law "$(DEMO_TRUE)" --from-rest \
		--integrator scipy --periods 30 --noise 0.01 --seed 2 --out $(DEMO)/low.csv
	@echo "== 2. the designer's linear law against the record: inconsistent, and where"
	$(BIN)/vidi verify --scenario $(DEMO)/high.toml --data $(DEMO)/high.csv \
		--law "$(DEMO_LAW)" --out $(DEMO)/verify
	@echo "== 3. discovery from both records: no polynomial of the library explains them"
	$(BIN)/vidi fit --scenario $(DEMO)/high.toml --scenario $(DEMO)/low.toml \
		--data $(DEMO)/high.csv --data $(DEMO)/low.csv --out $(DEMO)/fit
	@echo "== 4. explain from the linear start: the missing effect is named, the gap shrinks"
	$(BIN)/vidi explain --scenario $(DEMO)/high.toml --data $(DEMO)/high.csv \
		--out $(DEMO)/explain
	@echo "== 5. the reports"
	$(BIN)/vidi report $(DEMO)/verify
	$(BIN)/vidi report $(DEMO)/fit
	$(BIN)/vidi report $(DEMO)/explain
	@echo "demo done: read $(DEMO)/explain/report.pdf (or report.tex without TeX: make tex)"

# The shipped model-term selection study (120 runs, 4-10 min on two cores; resumable: run it
# again after an interruption), then its report
study: install
	$(BIN)/vidi study --config examples/study_paper.toml --out out/study
	$(BIN)/vidi report out/study

# TeX Live for `vidi report` PDFs (optional: without it the reports are .tex files)
tex:
	@if command -v latexmk >/dev/null && command -v pdftotext >/dev/null; then \
		echo "TeX Live is installed"; \
	else \
		SUDO=$$([ "$$(id -u)" = 0 ] || echo sudo); \
		$$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install \
			-y -qq --no-install-recommends $(TEX_PACKAGES); \
	fi

# The suite on every core (one worker per core; a module's tests share one worker, so its
# fixtures are built once); the long surveys carry the `slow` mark: `make test-slow`, in CI
JOBS ?= auto
PYTEST := $(BIN)/python -m pytest -q -n $(JOBS) --dist loadscope

test: install
	$(PYTEST) -m "not slow"

test-slow: install
	$(PYTEST) -m slow

test-all: install
	$(PYTEST)

# make bench also appends its run to docs/_measured/bench-history.jsonl and writes its scaling
# section to docs/_measured/scaling-bench.jsonl, then renders the tables made from them.
bench: install
	cd bench && ../$(BIN)/python run.py
	$(BIN)/python -m tests.tables

# The shipped paper study (examples/study_paper.toml) old against new, 3 pairs (about 25
# minutes on two cores): its own run in the bench history, its tables compared cell by cell.
bench-study: install
	cd bench && ../$(BIN)/python run.py paper-study
	$(BIN)/python -m tests.tables

# The corpus (../shared/corpus) old against new: every record verified with its true law,
# fitted and explained by both codes in turn (about 12 minutes on two cores), what each
# found compared with the other's and the truth; its own run in the bench history.
bench-corpus: install
	cd bench && ../$(BIN)/python run.py corpus
	$(BIN)/python -m tests.tables

# The measured tables of docs/validation.md and the README, rendered between their
# <!-- table:NAME --> markers from the surveys' saved runs in docs/_measured/ (seconds; each
# table names the commit and date of its runs; tests/test_tables.py holds the pages to it).
# `make surveys` runs the surveys again first: hours on two cores (SURVEY_WORKERS processes).
MEASURED := docs/_measured
SURVEY_WORKERS ?= 2
# the named contact models' survey: a run per seed, each 2 records of every model and 2
# polynomial laws (60 records in all)
CONTACT_SEEDS := 1 200 400 600 800

tables: install
	$(BIN)/python -m tests.tables

surveys: install
	rm -f $(MEASURED)/intervals-*.jsonl $(MEASURED)/advise-*.jsonl $(MEASURED)/realistic-*.jsonl \
		$(MEASURED)/corpus*.jsonl $(MEASURED)/contact-two-points*.jsonl \
		$(MEASURED)/contact-narrow-points*.jsonl \
		$(MEASURED)/explain-random*.jsonl $(MEASURED)/study-paper*.jsonl \
		$(MEASURED)/contact-models-*.jsonl $(MEASURED)/explain-cases*.jsonl \
		$(MEASURED)/calibration*.jsonl $(MEASURED)/memory-orbits*.jsonl \
		$(MEASURED)/effects*.jsonl $(MEASURED)/fit-sheet*.jsonl
	$(BIN)/python -m tests.survey_fit_sheet --draws 0 24 --workers $(SURVEY_WORKERS) \
		--out $(MEASURED)/fit-sheet.jsonl
	$(BIN)/python -m tests.survey_memory_orbits --n 160 --workers $(SURVEY_WORKERS) \
		--out $(MEASURED)/memory-orbits.jsonl
	$(BIN)/python -m tests.survey_effects --draws 0 40 --workers $(SURVEY_WORKERS) \
		--out $(MEASURED)/effects.jsonl
	$(BIN)/python -m tests.survey_calibration --n 3 --first-seed 900 \
		--out $(MEASURED)/calibration.jsonl
	$(BIN)/python -m tests.survey_calibration --n 4 --first-seed 903 \
		--out $(MEASURED)/calibration-903.jsonl
	$(BIN)/python -m tests.survey_intervals --records 64 --first 272 \
		--workers $(SURVEY_WORKERS) --out $(MEASURED)/intervals-272.jsonl
	$(BIN)/python -m tests.survey_intervals --records 64 --first 208 \
		--workers $(SURVEY_WORKERS) --out $(MEASURED)/intervals-208.jsonl
	$(BIN)/python -m tests.survey_intervals --corpus \
		--workers $(SURVEY_WORKERS) --out $(MEASURED)/intervals-corpus.jsonl
	$(BIN)/python -m tests.survey_advise --cases 0 14 --out $(MEASURED)/advise-1.jsonl
	$(BIN)/python -m tests.survey_advise --cases 0 12 --force-noise 0.03 \
		--out $(MEASURED)/advise-3.jsonl
	$(BIN)/python -m tests.realistic_survey --properties --n 25 --noise-seeds 2 \
		--out $(MEASURED)/realistic-properties.jsonl
	$(BIN)/python -m tests.realistic_survey --properties --n 8 --noise-seeds 1 \
		--out $(MEASURED)/realistic-default.jsonl
	$(BIN)/python -m tests.realistic_survey --properties --n 8 --noise-seeds 1 --field \
		--out $(MEASURED)/realistic-field.jsonl
	$(BIN)/python -m tests.survey_corpus --out $(MEASURED)/corpus.jsonl
	$(BIN)/python -m tests.survey_contact_models --models hunt-crossley lankarani-nikravesh \
		--per-model 10 --seed 1 --max-simulations 60 --second-point advised random --boot 0 \
		--out $(MEASURED)/contact-two-points.jsonl
	$(BIN)/python -m tests.survey_contact_models --models hunt-crossley lankarani-nikravesh \
		--per-model 10 --seed 1 --max-simulations 60 --second-point advised random --boot 0 \
		--amplitude-range 0.9 1.1 --frequency-range 0.95 1.05 \
		--out $(MEASURED)/contact-narrow-points.jsonl
	for seed in $(CONTACT_SEEDS); do \
		$(BIN)/python -m tests.survey_contact_models --seed $$seed --per-model 2 --poly 2 \
			--max-simulations 200 --boot 30 --workers $(SURVEY_WORKERS) \
			--out $(MEASURED)/contact-models-$$seed.jsonl || exit 1; \
	done
	$(BIN)/python -m tests.survey_explain --draws 0 60 --workers $(SURVEY_WORKERS) \
		--out $(MEASURED)/explain-random.jsonl
	$(BIN)/python -m tests.survey_explain_cases --out $(MEASURED)/explain-cases.jsonl
	$(BIN)/python -m tests.survey_study --workers $(SURVEY_WORKERS) \
		--out $(MEASURED)/study-paper.jsonl
	$(MAKE) tables

# The README's numbers and the demo's figures, measured as a user meets them: a fresh clone's
# make install, make demo (its figures into reports/assets), each README command timed, make
# test (about 20 min on two cores; the machine otherwise idle), then the pages rendered
readme: install
	$(BIN)/python -m tests.survey_readme --install --test --out $(MEASURED)/readme.jsonl
	$(MAKE) tables

# The gallery's other figures (reports/assets; the demo's come with `make readme`): advise,
# landscape and Ueda's attractor on the demo's machine
gallery: demo
	$(BIN)/vidi advise --scenario $(DEMO)/high.toml --law "$(DEMO_LAW)" --law "$(DEMO_TRUE)" \
		--noise 0.01 --amplitude 3e5:6e5 --frequency 20:30 --grid 5x5 --out $(DEMO)/advise --overwrite
	cp $(DEMO)/advise/advise_map.png reports/assets/demo_advise_map.png
	$(BIN)/vidi landscape --scenario $(DEMO)/high.toml --data $(DEMO)/high.csv --grid 21x21 \
		--out $(DEMO)/landscape --overwrite
	cp $(DEMO)/landscape/landscape.png reports/assets/demo_landscape.png
	$(BIN)/vidi ueda attractor --model negres --out $(DEMO)/ueda --overwrite
	cp $(DEMO)/ueda/attractor.png reports/assets/ueda_attractor.png

# The documentation site (docs/*.md, API reference from the docstrings), warnings as errors
docs: install
	$(BIN)/sphinx-build -W --keep-going -b html docs docs/_build/html

lint: install
	$(BIN)/ruff check discovery constraints reports tests bench
	$(BIN)/ruff format --check discovery constraints reports tests bench

clean:
	rm -rf out bench/_work .pytest_cache docs/_build docs/_generated
