# mk/faults.mk - fault injection in the simulator (issue 9, docs/FAULTS.md):
# hs_faults (in librfs_host.a), its CMocka test, the CLI test and `make bench-faults`.

# The hooks alone and whole runs of the open-hall fault scenarios, log read back.
$(eval $(call cmocka_test,test_faults,tests/host_sim/test_faults.c,))

# rfseek-sim on every fault scenario for 3 seeds, and bad `faults:` sections.
TEST_SCRIPTS += 'tests/host_sim/faults.sh $(BUILD)/bin/rfseek-sim 3'

# The table of docs/FAULTS.md: every fault over 50 seeds, with and without it, side by side.
FAULT_SEEDS ?= 50
.PHONY: bench-faults
bench-faults: $(BUILD)/bin/rfseek-sim
	@$(PYTHON) scripts/fault_table.py --sim $(BUILD)/bin/rfseek-sim --seeds $(FAULT_SEEDS)
BENCH_TARGETS += bench-faults
