# Two entry points on a fresh machine: `make run` and `make test`.
PY      ?= python3
VENV    := .venv
BIN     := $(VENV)/bin
STAMP   := $(VENV)/.installed-stamp
# The Python sources ruff lints and formats.
PYSRC   := acld_gym baselines train tests benchmarks studies setup.py .ci

.PHONY: install run studies test test-slow docs wheel-check lint format bench agents clean

$(STAMP): pyproject.toml constraints.txt setup.py acld_gym/envs/_stepcore.c
	$(PY) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	# The build needs (setup.py: numpy's headers for the compiled step) come from the
	# constraints too, so the package is built without an isolated build environment.
	$(BIN)/pip install --quiet -c constraints.txt setuptools numpy
	# torch is pinned (constraints.txt) to the CPU build; an unpinned torch pulls CUDA.
	$(BIN)/pip install --quiet --no-build-isolation -c constraints.txt -e ".[all,dev,docs]"
	touch $(STAMP)

install: $(STAMP)

## Reproduce the thesis (Table 2, figures, on its own mesh), then on ACLDBeam-v1 (the
## mesh-converged beam): evaluate the reference policies and the bound, and compare the
## shipped agents with them (thesis cases + held-out random loads). A progress line
## shows on a terminal. The score here is a reduced one, on the first RUN_SCORE_EPISODES
## episodes of the test set (its heading says so); `make studies` scores every policy on
## all 100.
RUN_SCORE_EPISODES ?= 20
run: $(STAMP)
	$(BIN)/acld-gym reproduce --json results/table2.json --plots results/figures
	$(BIN)/acld-gym evaluate --score-episodes $(RUN_SCORE_EPISODES) --json results/baselines.json --plots results/figures
	$(BIN)/acld-gym compare --score-episodes $(RUN_SCORE_EPISODES) --json results/compare.json --plots results/figures

## The README's slower studies: mesh convergence and the thesis mesh against the converged
## plant, the baselines' stability at every corner of the parameter box, and every policy
## in control terms with its score (modes, peaks, margins, effort; ~4 min).
studies: $(STAMP)
	$(BIN)/acld-gym mesh --json results/mesh.json
	$(BIN)/acld-gym robustness
	$(BIN)/acld-gym analyze passive lqr smc mpc $(dir $(wildcard train/agents/*/metadata.json)) --json results/analysis.json --markdown results/analysis.md --plots results/figures

## Retrain the repository's shipped ACLDBeam-v1 agents (train/agents/vrs, ppo, sac), from
## scratch (no teacher): the benchmark's runs of vrs, ppo and sac (5 seeds each, resumable),
## then ship vrs seed 0 and the ppo and sac seeds that are best on the thesis cases over the
## ones in train/agents (docs/training.md, "Reinforcement learning from scratch"), and write
## their comparison, train/agents/compare.json and .md, which tests/train/test_agents.py
## checks them against. The pages that quote those agents (docs/training.md, the README's
## score table) are then to be brought up to date: the tests say where they differ.
agents: $(STAMP)
	$(BIN)/acld-gym benchmark --algos vrs ppo sac --seeds 0 1 2 3 4 --resume --out runs/benchmark/v1
	$(BIN)/acld-gym ship runs/benchmark/v1/agents/vrs-s0 vrs --agents train/agents --force
	$(BIN)/acld-gym ship runs/benchmark/v1 ppo --best ppo --agents train/agents --force
	$(BIN)/acld-gym ship runs/benchmark/v1 sac --best sac --agents train/agents --force
	$(BIN)/acld-gym compare --json train/agents/compare.json --markdown train/agents/compare.md

## ruff: lint, and the format check (`make format` applies it).
lint: $(STAMP)
	$(BIN)/ruff check $(PYSRC)
	$(BIN)/ruff format --check $(PYSRC)

## Lint + the test suite (slow tests excluded; see test-slow) + the documentation site.
## pytest-xdist spreads the tests over the cores (work stealing: a core left idle takes
## tests queued for the other); the 15 slowest are listed at the end; the session's
## temporary files go into one folder it removes (tests/conftest.py).
test: lint
	$(BIN)/python -m pytest -q -n auto --dist worksteal --durations=15
	$(MAKE) docs

## The core install: the wheel (compiled step, shipped agents as package data) in a clean
## venv without extras (no torch, no osqp), checked from outside the checkout.
WHEEL_VENV ?= /tmp/acld-gym-core-venv
wheel-check: $(STAMP)
	rm -rf build dist $(WHEEL_VENV)
	$(BIN)/pip wheel --quiet --no-deps --no-build-isolation -w dist .
	$(PY) -m venv $(WHEEL_VENV)
	$(WHEEL_VENV)/bin/pip install --quiet -c constraints.txt dist/acld_gym-*.whl
	! $(WHEEL_VENV)/bin/python -c "import torch" 2>/dev/null
	! $(WHEEL_VENV)/bin/python -c "import osqp" 2>/dev/null
	cp .ci/core_install_check.py $(WHEEL_VENV)/
	cd $(WHEEL_VENV) && bin/python core_install_check.py --compiled
	rm -rf $(WHEEL_VENV)  # nothing left in /tmp (the check failing leaves it to inspect)

## The documentation site (mkdocs.yml, docs/) into site/, strict: any warning fails.
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict

test-slow: $(STAMP)
	$(BIN)/python -m pytest -q -n auto --dist worksteal --durations=15 -m slow

format: $(STAMP)
	$(BIN)/ruff check --fix $(PYSRC)
	$(BIN)/ruff format $(PYSRC)

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_reproduce.py
	$(BIN)/python benchmarks/bench_env.py
	$(BIN)/python benchmarks/bench_bound.py
	$(BIN)/python benchmarks/bench_train.py --timesteps 32768 --n-envs 8
	$(BIN)/python benchmarks/bench_run.py

clean:
	rm -rf $(VENV) results .pytest_cache site build dist
