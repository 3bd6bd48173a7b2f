# The two commands of the quick start; each sets up .venv on first use.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp
RAY_STAMP := $(VENV)/.ray-stamp
LEARN_STAMP := $(VENV)/.learn-stamp
export MUJOCO_GL ?= disable

.PHONY: demo test check bench bench-ci lint models ray learn clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

# The Ray extra (haptic bench --backend ray), pinned in pyproject.toml; CI installs it.
$(RAY_STAMP): $(STAMP) pyproject.toml
	$(BIN)/python -m pip install --quiet -e '.[dev,ray]'
	touch $(RAY_STAMP)

ray: $(RAY_STAMP)

# The learning extra (scripts/train_ppo.py, haptic bench --policy learned:PATH), pinned in pyproject.toml.
$(LEARN_STAMP): $(STAMP) pyproject.toml
	$(BIN)/python -m pip install --quiet -e '.[dev,learn]'
	touch $(LEARN_STAMP)

learn: $(LEARN_STAMP)

demo: $(STAMP)
	$(BIN)/haptic models list
	@echo
	$(BIN)/haptic explore --object WEDGE01 --executor physics --seed 1 --record out/demo.rrd --json out/demo.json

test: $(STAMP)
	$(BIN)/python -m pytest -n 2 -p no:cacheprovider

# The quick check while editing: ruff and the pure core's tests (geometry, matching, planning) but those marked
# slow (whole episodes, searches); `make test` runs everything.
check: $(STAMP)
	$(BIN)/ruff check haptic tests scripts
	$(BIN)/python -m pytest -n 2 -p no:cacheprovider -m "not slow" tests/geometry tests/matching tests/planning

bench: $(STAMP)
	$(BIN)/haptic bench --episodes 200 --policy planner,greedy,random --seed 1 --workers 2 --force --out out/bench/seed.jsonl
	$(BIN)/haptic bench --models assets/libraries/lookalike --episodes 200 --policy planner,greedy,random --seed 1 \
		--workers 2 --force --out out/bench/lookalike.jsonl

bench-ci: $(STAMP)
	$(BIN)/haptic bench --episodes 40 --policy planner,random --seed 1 --workers 2 --verify none --no-plot --force \
		--out out/ci/seed.jsonl

lint: $(STAMP)
	$(BIN)/ruff check haptic tests scripts

models: $(STAMP)
	$(BIN)/python scripts/make_models.py

clean:
	rm -rf $(VENV) .pytest_cache .ruff_cache build *.egg-info
