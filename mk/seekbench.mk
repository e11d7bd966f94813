# Seeking-efficacy benchmark (issue 7): every strategy on every shipped scenario, noise
# and shadowing sweeps, internal models, bridging -> docs/RESULTS.md, docs/figures/seek_*.
# Not part of `make test` (minutes); a 2-seed smoke run of the same script is.
#   make bench-seek [SEEK_SEEDS=200] [SEEK_MODEL_SEEDS=200] [SEEK_SLOW_SEEDS=30] [SEEK_JOBS=2]
SEEK_SEEDS ?= 200
SEEK_MODEL_SEEDS ?= $(SEEK_SEEDS)
SEEK_SLOW_SEEDS ?= 30
SEEK_JOBS ?= 2

.PHONY: bench-seek
bench-seek: $(BUILD)/bin/rfseek-sim
	$(PYTHON) scripts/bench_seek.py --bin $(BUILD)/bin/rfseek-sim --seeds $(SEEK_SEEDS) \
		--model-seeds $(SEEK_MODEL_SEEDS) --slow-model-seeds $(SEEK_SLOW_SEEDS) \
		--jobs $(SEEK_JOBS)

TEST_SCRIPTS += "$(PYTHON) scripts/bench_seek.py --smoke --jobs 2 --bin $(BUILD)/bin/rfseek-sim"
TEST_SCRIPTS += "tests/host_sim/strategy_cli.sh $(BUILD)/bin/rfseek-sim"
