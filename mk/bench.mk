# mk/bench.mk - `make bench`: the figures of docs/PERFORMANCE.md and docs/RESULTS.md.
# Each bench-* target prints one block; `make bench` runs them all (minutes).
# The bench programs are built by `make` so they cannot rot.
BENCH_BIN := $(BUILD)/bin

# --- the core: worst-case iteration, data path, models, path loss (callgrind, exact) -------
# $(call bench_prog,NAME,LAYER): bench/NAME.c linked with LAYER's libraries.
define bench_prog
$(BENCH_BIN)/$(1): bench/$(1).c $$(LIBS_$(2))
	@mkdir -p $$(@D)
	$$(LD_$(2)) $$(HOST_CFLAGS) $$(INC_$(2)) $$(DEPFLAGS) -MF $$@.d -MT $$@ $$< -o $$@ $$(LIBS_$(2)) $$(LDLIBS_$(2))
ALL_TARGETS += $(BENCH_BIN)/$(1)
endef
$(eval $(call bench_prog,bench_core,core))
$(eval $(call bench_prog,bench_ridge,core))
$(eval $(call bench_prog,bench_models,core))
$(eval $(call bench_prog,bench_pathloss,linux))

.PHONY: bench-core bench-data bench-models bench-pathloss
# The core's worst-case iteration: callgrind instructions, wall time against scikit-learn.
bench-core: $(BENCH_BIN)/bench_core
	@scripts/bench_core.sh $(BUILD)
# The data path: fixed point, RSSI window, sample store, ridge model, targets.
bench-data: $(BENCH_BIN)/bench_ridge $(BUILD)/arm/lib/librfs_core.a
	@scripts/bench_data.sh $(BUILD)
# Instruction counts per full relearn, per grid search and per fit slice.
bench-models: $(BENCH_BIN)/bench_models
	@scripts/bench_models.sh $(BUILD)
BENCH_TARGETS += bench-core bench-data bench-models bench-pathloss
# Every bench program's quick modes run to the end in `make test`.
$(eval $(call test_script,bench_modes,tests/bench/bench_modes.sh $(BUILD),$(BENCH_BIN)/bench_core $(BENCH_BIN)/bench_ridge $(BENCH_BIN)/bench_models $(BENCH_BIN)/bench_pathloss))

# The path-loss model: instructions per relearn, per slice and per prediction, state bytes.
PATHLOSS_BENCH_MAP ?= scenarios/maps/office.yaml
# $(call pathloss_ir,NAME,ARGS): instructions counted inside the toggled region; the
# program's own output is left in $tmp/NAME.out.
define pathloss_ir
valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file=$$tmp/$(1).cg \
    $(BUILD)/bin/bench_pathloss $(PATHLOSS_BENCH_MAP) $(2) > $$tmp/$(1).out 2>/dev/null; \
callgrind_annotate $$tmp/$(1).cg 2>/dev/null | awk '/PROGRAM TOTALS/ {gsub(",","",$$1); print $$1}'
endef
# $(call pathloss_row,NAME,ARGS,LABEL): one table row.
define pathloss_row
ir=$$($(call pathloss_ir,$(1),$(2))); o=$$tmp/$(1).out; \
v() { awk -v k=$$1 '$$1 == k {print $$2}' $$o; }; \
printf "  %-34s %5s %5s %8s %8s %13s %9s\n" "$(3)" $$(v bins) $$(v candidates) $$(v walls_counted) \
    $$(v footprints_cached) $$ir $$(awk -v a=$$ir -v u=$$(v walls_counted) 'BEGIN{printf "%.0f", a/(u>0?u:1)}')
endef

.PHONY: bench-pathloss
bench-pathloss: $(BUILD)/bin/bench_pathloss
	@set -e; tmp=$$(mktemp -d); trap 'rm -rf "$$tmp"' EXIT; \
	echo "pathloss: $(PATHLOSS_BENCH_MAP) (core grid 0.1 m), host x86-64 instructions (callgrind, exact)"; \
	printf "  %-34s %5s %5s %8s %8s %13s %9s\n" workload bins cands counted cached "instructions" "per count"; \
	$(call pathloss_row,r1,relearn 1000,whole floor 1000 samples fresh); \
	$(call pathloss_row,r10,relearn 10000,whole floor 10000 samples fresh); \
	$(call pathloss_row,p150,path 150,walk 150 steps fresh); \
	$(call pathloss_row,w150,pathwarm 150,walk 150 steps cache warm); \
	$(call pathloss_row,p400,path 400,walk 400 steps fresh); \
	$(call pathloss_row,w400,pathwarm 400,walk 400 steps cache warm); \
	grep -h '^state_bytes\|^coarse' $$tmp/r10.out | sed 's/^/  /'; \
	for bud in 2000 20000; do \
	    ir=$$($(call pathloss_ir,s$$bud,slice 10000 $$bud)); \
	    echo "  whole floor 10000 samples: first slice of budget $$bud units: $$ir instructions; whole fit in $$(awk '/^calls/ {print $$2}' $$tmp/s$$bud.out) calls"; \
	done; \
	ir=$$($(call pathloss_ir,p,predict 10000)); echo "  one prediction (the relearn check): $$ir instructions"

# --- seeking efficacy: every strategy on every shipped scenario, noise and shadowing
# sweeps, internal models, bridging -> docs/RESULTS.md, docs/figures/seek_*. `make test`
# runs a 2-seed smoke run of the same script.
#   make bench-seek [SEEK_SEEDS=200] [SEEK_MODEL_SEEDS=200] [SEEK_SLOW_SEEDS=30] [SEEK_JOBS=2]
SEEK_SEEDS ?= 200
SEEK_MODEL_SEEDS ?= $(SEEK_SEEDS)
SEEK_SLOW_SEEDS ?= 30
SEEK_JOBS ?= 2
.PHONY: bench-seek
bench-seek: $(BENCH_BIN)/rfseek-sim
	$(PYTHON) scripts/bench_seek.py --bin $(BENCH_BIN)/rfseek-sim --seeds $(SEEK_SEEDS) \
		--model-seeds $(SEEK_MODEL_SEEDS) --slow-model-seeds $(SEEK_SLOW_SEEDS) \
		--jobs $(SEEK_JOBS)
$(eval $(call test_script,bench_seek_smoke,$(PYTHON) scripts/bench_seek.py --smoke --jobs 2 --bin $(BENCH_BIN)/rfseek-sim,$(BENCH_BIN)/rfseek-sim))

# --- the simulator, map and planner, faults --------------------------------------------------
.PHONY: bench-sim bench-map bench-faults
# Real-time factor of one robot and one 200 pkt/s source on one core; a 200-seed batch;
# meta + ridge and meta-path + pathloss on the office and the Intel lab, beside
# BENCH_SIM_BASE (another build's rfseek-sim) when given.
BENCH_SIM_BASE ?=
bench-sim: $(BENCH_BIN)/rfseek-sim
	@scripts/bench_sim.sh $(BENCH_BIN)/rfseek-sim $(BENCH_SIM_BASE)
# Planner and legal-grid figures on the office scenario map and on the Intel lab
# (docs/PERFORMANCE.md, "Map, planner, drive").
bench-map: $(BENCH_BIN)/rfseek-map
	@for m in scenarios/maps/office.yaml scenarios/maps/intel.yaml; do \
	    if [ -e $$m ]; then $(BENCH_BIN)/rfseek-map $$m --bench 200 | grep -E '^(map|core grid|lattice|bench|  )'; fi; done
# The table of docs/FAULTS.md: every fault over 50 seeds, with and without it, side by side.
FAULT_SEEDS ?= 50
bench-faults: $(BENCH_BIN)/rfseek-sim
	@$(PYTHON) scripts/fault_table.py --sim $(BENCH_BIN)/rfseek-sim --seeds $(FAULT_SEEDS)
BENCH_TARGETS += bench-sim bench-map bench-faults

# The drive under localisation noise -> docs/RESULTS.md ("The drive under localisation
# noise"): 3 floors x 10 localisation settings x 2 configurations x 200 held-out seeds.
# `make test` runs a 2-seed smoke run of the same script.
.PHONY: bench-drive
bench-drive: $(BENCH_BIN)/rfseek-sim
	$(PYTHON) scripts/bench_drive.py --sim $(BENCH_BIN)/rfseek-sim
BENCH_TARGETS += bench-drive
$(eval $(call test_script,bench_drive_smoke,$(PYTHON) scripts/bench_drive.py --smoke --jobs 2 --sim $(BENCH_BIN)/rfseek-sim,$(BENCH_BIN)/rfseek-sim))

# Seeking at random placements on every shipped floor, meta-path + pathloss and meta +
# ridge -> docs/RESULTS.md ("Generalisation: random placements", held-out draws only).
# Long (about an hour on two shared cores); GENERAL_ARGS="--placements 20" makes it short.
GENERAL_JOBS ?= 1
GENERAL_ARGS ?=
.PHONY: bench-general
bench-general: $(BENCH_BIN)/rfseek-sim
	nice -n 19 $(PYTHON) scripts/bench_general.py --sim $(BENCH_BIN)/rfseek-sim --jobs $(GENERAL_JOBS) $(GENERAL_ARGS)
BENCH_TARGETS += bench-general

# Bridging (paper section 6) on every bridging scenario -> docs/RESULTS.md ("Bridging"),
# docs/figures/seek_bridge.png: the paper's meta + ridge beside one fit per node, 200
# held-out seeds. `make test` runs a one-seed smoke run of the same script.
BRIDGE_SEEDS ?= 1001..1200
BRIDGE_JOBS ?= 2
.PHONY: bench-bridge
bench-bridge: $(BENCH_BIN)/rfseek-sim
	$(PYTHON) scripts/bench_bridge.py --sim $(BENCH_BIN)/rfseek-sim --seeds $(BRIDGE_SEEDS) \
		--jobs $(BRIDGE_JOBS)
BENCH_TARGETS += bench-bridge
$(eval $(call test_script,bench_bridge_smoke,$(PYTHON) scripts/bench_bridge.py --smoke --jobs 2 --sim $(BENCH_BIN)/rfseek-sim,$(BENCH_BIN)/rfseek-sim))

# --- the Linux port: pcap feeder, CAN codec and the two-process overhead ---------------------
.PHONY: bench-feed bench-wire
# Frames/s extracting one MAC's RSSI from a 1,000,000-frame capture, side by side with
# tshark and with a count-only read of the same file (medians).
bench-feed: $(BENCH_BIN)/rfseek-feed $(FEED)/feed_writegen $(FEED)/feed_count
	@tests/feed/bench_feed.sh $(BENCH_BIN)/rfseek-feed $(FEED)/feed_writegen $(FEED)/bench $(FEED)/feed_count
# Codec instructions (callgrind) and rfseekd against the in-process controller.
$(BUILD)/tests/wire/bench_can: tests/wire/bench_can.c $(CORE_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(INC_core) $(DEPFLAGS) -MF $@.d -MT $@ $< -o $@ $(CORE_LIB)
bench-wire: $(BUILD)/tests/wire/bench_can $(BENCH_BIN)/rfseekd $(BENCH_BIN)/rfseek-sim-lcm $(BENCH_BIN)/rfseek-sim
	@tests/wire/bench_wire.sh $(BUILD)
BENCH_TARGETS += bench-feed bench-wire

# --- the Cortex-M4 (emulated): instruction counts of the loop and of the models ----------------
.PHONY: bench-firmware bench-models-m4
bench-firmware: $(FW)/bench.elf $(FW)/bench_models.elf $(FW)/firmware.elf $(FW)/qemu.elf
	@tests/firmware/bench.sh $(BUILD)
# MW_BUDGETS="mlp:600 pathloss:800" adds sliced relearns at candidate budgets beside the
# registry's (how rfs_models_entry_t.mcu_fit_budget was chosen; up to 8 pairs).
MW_BUDGETS ?=
bench-models-m4: $(FW)/bench_models.elf
	@tests/firmware/bench_models.sh bench $(BUILD) $(MW_BUDGETS)
BENCH_TARGETS += bench-firmware bench-models-m4
