# mk/sweep.mk - the simulator under ASan+UBSan over many seeds (issue 9,
# docs/RELIABILITY.md): zero sanitizer reports allowed.
#   make sweep [SWEEP_SEEDS=200] [SWEEP_SCENARIOS="scenarios/default.yaml ..."]
# `make test` runs a 5-seed version.
SWEEP_SIM := $(BUILD)/asan/bin/rfseek-sim
SWEEP_SEEDS ?= 200
# Faults enabled (issue 9): the office with each fault of scenarios/faults/, and without.
SWEEP_SCENARIOS ?= scenarios/default.yaml $(sort $(wildcard scenarios/faults/office-*.yaml))

# rfseek-sim linked against the ASan+UBSan builds of the host and core libraries.
# (Depends on the plain program too, so generated headers of later fragments exist.)
$(SWEEP_SIM): host_sim/prog/rfseek-sim.c $(HOST_ASAN_LIB) $(CORE_ASAN_LIB) $(BUILD)/bin/rfseek-sim
	@mkdir -p $(@D) $(BUILD)/asan/obj
	$(CC) $(HOST_CFLAGS) -O1 $(SAN_FLAGS) -c $< -o $(BUILD)/asan/obj/rfseek-sim.main.o
	$(HOST_LINK) $(SAN_FLAGS) -o $@ $(BUILD)/asan/obj/rfseek-sim.main.o $(HOST_ASAN_LIB) $(CORE_ASAN_LIB) $(HOST_LDLIBS)

.PHONY: sweep
sweep: $(SWEEP_SIM)
	@scripts/san_sweep.sh $(SWEEP_SIM) $(SWEEP_SEEDS) $(SWEEP_SCENARIOS)

TEST_DEPS += $(SWEEP_SIM)
TEST_SCRIPTS += "scripts/san_sweep.sh $(SWEEP_SIM) 3 scenarios/default.yaml scenarios/faults/office-kidnap.yaml scenarios/faults/office-rssi_silence.yaml scenarios/faults/office-bus_off.yaml"
