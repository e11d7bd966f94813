# mk/fuzz.mk - libFuzzer targets for the parsers of outside input (issue 9,
# docs/RELIABILITY.md): CAN frames, LCM messages and logs, map YAML + PGM, scenario YAML.
# The radiotap (mk/feed.mk) and replay-stream (mk/firmware.mk) targets are their owners';
# `make fuzz` runs all six. clang only: -fsanitize=fuzzer,address,undefined.
#   make fuzz [FUZZ_SECONDS=300] [FUZZ_TARGETS="can map"]   each target for that long
# New inputs go to $(BUILD)/fuzz/corpus-<name>, crashes to $(BUILD)/fuzz/artifacts/.
FUZZ_CC ?= clang
FUZZ_SECONDS ?= 300
FUZZ_DIR := $(BUILD)/fuzz
FUZZ_SAN := -fsanitize=address,undefined -fno-sanitize-recover=all
FUZZ_CFLAGS := $(CSTD) $(WARN) -D_DEFAULT_SOURCE -g -O1 -Icommon -Ihost_sim -I$(BUILD)/gen -Itests/fuzz $(FUZZ_SAN)
FUZZ_HDRS := tests/fuzz/fuzz_tmp.h $(CORE_HDRS) $(wildcard host_sim/*.h)
FUZZ_YAML_LIBS := $(shell pkg-config --libs yaml-0.1 2>/dev/null || echo -lyaml)
FUZZ_LCM_LIBS := $(shell pkg-config --libs lcm 2>/dev/null || echo -llcm)

FUZZ_OWN := can lcm map scenario
FUZZ_BINS := $(FUZZ_OWN:%=$(FUZZ_DIR)/fuzz_%)

$(FUZZ_DIR)/fuzz_can: tests/fuzz/fuzz_can.c $(CORE_SRCS) $(FUZZ_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(CORE_SRCS) -o $@

FUZZ_MAP_SRCS := firmware/port/linux/lx_map.c firmware/port/linux/lx_err.c
$(FUZZ_DIR)/fuzz_map: tests/fuzz/fuzz_map.c $(FUZZ_MAP_SRCS) $(CORE_SRCS) $(FUZZ_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(FUZZ_MAP_SRCS) $(CORE_SRCS) -o $@ $(FUZZ_YAML_LIBS) -lm

FUZZ_SCN_SRCS := host_sim/hs_scenario.c firmware/port/linux/lx_err.c host_sim/hs_radio.c host_sim/hs_motor.c \
    $(wildcard host_sim/hs_faults.c)
$(FUZZ_DIR)/fuzz_scenario: tests/fuzz/fuzz_scenario.c $(FUZZ_SCN_SRCS) $(CORE_SRCS) $(FUZZ_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(FUZZ_SCN_SRCS) $(CORE_SRCS) -o $@ $(FUZZ_YAML_LIBS) -lm

# The lcm-gen sources (from mk/wire.mk's rule, which is read after this file) have unused
# parameters: no -Werror for them.
FUZZ_LCM_NAMES := $(patsubst lcm/%.lcm,rfseek_%,$(sort $(wildcard lcm/*.lcm)))
FUZZ_LCM_GEN_OBJS := $(FUZZ_LCM_NAMES:%=$(FUZZ_DIR)/gen/%.o)
FUZZ_LCM_GEN_HDRS := $(FUZZ_LCM_NAMES:%=$(BUILD)/gen/%.h)
$(FUZZ_DIR)/gen/%.o: $(BUILD)/gen/%.c $(FUZZ_LCM_GEN_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(CSTD) -g -O1 -I$(BUILD)/gen $(FUZZ_SAN) -fsanitize=fuzzer-no-link -c $< -o $@
$(FUZZ_DIR)/fuzz_lcm: tests/fuzz/fuzz_lcm.c firmware/port/linux/lx_lcm.c firmware/port/linux/lx_err.c $(FUZZ_LCM_GEN_OBJS) $(CORE_SRCS) $(FUZZ_HDRS) $(FUZZ_LCM_GEN_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< firmware/port/linux/lx_lcm.c firmware/port/linux/lx_err.c $(FUZZ_LCM_GEN_OBJS) $(CORE_SRCS) -o $@ $(FUZZ_LCM_LIBS) -lm

# make test: each target over its committed corpus plus a short burst of new inputs.
FUZZ_TEST_RUNS ?= 5000
TEST_DEPS += $(FUZZ_BINS)
TEST_SCRIPTS += "tests/fuzz/run_all.sh $(BUILD) --runs $(FUZZ_TEST_RUNS) $(FUZZ_OWN)"

# make fuzz: every target (ours, radiotap, replay) for FUZZ_SECONDS each.
FUZZ_ALL_BINS := $(FUZZ_BINS) $(BUILD)/feed/fuzz_radiotap $(BUILD)/firmware/fuzz_replay
FUZZ_TARGETS ?= $(FUZZ_OWN) radiotap replay
.PHONY: fuzz fuzz-build
fuzz-build: $(FUZZ_ALL_BINS)
fuzz: fuzz-build
	@tests/fuzz/run_all.sh $(BUILD) --seconds $(FUZZ_SECONDS) $(FUZZ_TARGETS)
