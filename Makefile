# Two entry points on a fresh machine: `make run` and `make test`.
PY      ?= python3
VENV    := .venv
BIN     := $(VENV)/bin
STAMP   := $(VENV)/.installed-stamp

.PHONY: install run test test-slow lint format bench agents clean

$(STAMP): pyproject.toml constraints.txt setup.py acld_gym/envs/_stepcore.c
	$(PY) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	# The build needs (setup.py: numpy's headers for the compiled step) come from the
	# constraints too, so the package is built without an isolated build environment.
	$(BIN)/pip install --quiet -c constraints.txt setuptools numpy
	# torch is pinned (constraints.txt) to the CPU build; an unpinned torch pulls CUDA.
	$(BIN)/pip install --quiet --no-build-isolation -c constraints.txt -e ".[all,dev]"
	touch $(STAMP)

install: $(STAMP)

## Reproduce the thesis (Table 2, figures), evaluate the reference policies in the env,
## then compare the shipped PPO/SAC agents with them (thesis cases + held-out random loads).
run: $(STAMP)
	$(BIN)/acld-gym reproduce --json results/table2.json --plots results/figures
	$(BIN)/python -m baselines.evaluate --json results/baselines.json --plots results/figures
	$(BIN)/python -m train.compare --json results/compare.json --plots results/figures

## Retrain the shipped agents (the commands in train/agents/*/metadata.json; about a
## minute each on 2 cores). The shipped files are each run's best/ checkpoint.
agents: $(STAMP)
	$(BIN)/python -m train ppo --seed 0 --out runs/ppo --no-progress
	$(BIN)/python -m train sac --seed 0 --out runs/sac --no-progress
	$(BIN)/python -m train ppo --seed 0 --param-noise 0.1 --out runs/ppo_robust --no-progress
	$(BIN)/python -m train sac --seed 0 --param-noise 0.1 --out runs/sac_robust --no-progress
	for a in ppo sac ppo_robust sac_robust; do $(BIN)/python -m train.ship runs/$$a $$a; done

## Lint + the test suite (slow tests excluded; see test-slow).
test: $(STAMP)
	$(BIN)/ruff check acld_gym baselines train tests benchmarks
	$(BIN)/python -m pytest -q

test-slow: $(STAMP)
	$(BIN)/python -m pytest -q -m slow

format: $(STAMP)
	$(BIN)/ruff format acld_gym baselines train tests benchmarks
	$(BIN)/ruff check --fix acld_gym baselines train tests benchmarks

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_reproduce.py
	$(BIN)/python benchmarks/bench_env.py
	$(BIN)/python benchmarks/bench_train.py --timesteps 32768 --n-envs 8

clean:
	rm -rf $(VENV) results .pytest_cache
