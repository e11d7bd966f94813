# mk/fuzz.mk - libFuzzer targets for the parsers of outside input (docs/RELIABILITY.md):
# CAN frames, LCM messages and logs, map YAML + PGM, PNG map images, scenario YAML,
# radiotap + 802.11 headers, the replay stream, pcap/pcapng captures, the pose CSV of
# rfseek-feed --pose and candump -L log lines. clang only:
# -fsanitize=fuzzer,address,undefined.
#   make fuzz [FUZZ_SECONDS=300] [FUZZ_TARGETS="can map"]   each target for that long
#   make fuzz-long [FUZZ_LONG_RUNS=10000000]   each target for that many executions, one after
#   another under nice -n 19 (the figures in docs/RELIABILITY.md, "Fuzz targets")
# New inputs go to $(FUZZ_DIR)/corpus-<name>, crashes to $(FUZZ_DIR)/artifacts/; `make test`
# runs each over its committed corpus plus a short burst.
FUZZ_CC ?= clang
FUZZ_SECONDS ?= 300
FUZZ_SAN := -fsanitize=address,undefined -fno-sanitize-recover=all
FUZZ_CFLAGS := $(CSTD) $(WARN) -D_DEFAULT_SOURCE -g -O1 $(INC_sim) -Itests/fuzz $(FUZZ_SAN)
FUZZ_HDRS := tests/fuzz/fuzz_tmp.h $(wildcard common/*.h firmware/*.h firmware/port/linux/*.h host_sim/*.h)
FUZZ_LX := firmware/port/linux

FUZZ_OWN := can lcm map png scenario pcap poses candump
FUZZ_BINS := $(FUZZ_OWN:%=$(FUZZ_DIR)/fuzz_%)

$(FUZZ_DIR)/fuzz_can: tests/fuzz/fuzz_can.c $(CORE_SRCS) $(FUZZ_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(CORE_SRCS) -o $@

FUZZ_MAP_SRCS := $(FUZZ_LX)/lx_map.c $(FUZZ_LX)/lx_pgm.c $(FUZZ_LX)/lx_png.c $(FUZZ_LX)/lx_yaml.c $(FUZZ_LX)/lx_err.c
$(FUZZ_DIR)/fuzz_map $(FUZZ_DIR)/fuzz_png: $(FUZZ_DIR)/fuzz_%: tests/fuzz/fuzz_%.c $(FUZZ_MAP_SRCS) $(CORE_SRCS) $(FUZZ_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) $(PNG_CFLAGS) -fsanitize=fuzzer $< $(FUZZ_MAP_SRCS) $(CORE_SRCS) -o $@ $(YAML_LIBS) $(PNG_LIBS) -lm

FUZZ_SCN_SRCS := host_sim/hs_scenario.c host_sim/hs_radio.c host_sim/hs_motor.c \
	host_sim/hs_faults.c $(FUZZ_LX)/lx_yaml.c $(FUZZ_LX)/lx_err.c
$(FUZZ_DIR)/fuzz_scenario: tests/fuzz/fuzz_scenario.c $(FUZZ_SCN_SRCS) $(CORE_SRCS) $(FUZZ_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(FUZZ_SCN_SRCS) $(CORE_SRCS) -o $@ $(YAML_LIBS) -lm

FUZZ_PCAP_SRCS := $(FUZZ_LX)/lx_pcap.c
$(FUZZ_DIR)/fuzz_pcap: tests/fuzz/fuzz_pcap.c $(FUZZ_PCAP_SRCS) $(FUZZ_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(FUZZ_PCAP_SRCS) -o $@ $(PCAP_LIBS)

FUZZ_POSES_SRCS := host_sim/hs_poses.c
$(FUZZ_DIR)/fuzz_poses: tests/fuzz/fuzz_poses.c $(FUZZ_POSES_SRCS) $(FUZZ_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(FUZZ_POSES_SRCS) -o $@ -lm

$(FUZZ_DIR)/fuzz_candump: tests/fuzz/fuzz_candump.c $(FUZZ_LX)/lx_candump.c $(FUZZ_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(FUZZ_LX)/lx_candump.c -o $@

# The lcm-gen sources (mk/linux.mk's rule) have unused parameters: no -Werror for them.
FUZZ_LCM_GEN_OBJS := $(LCM_GEN_NAMES:%=$(FUZZ_DIR)/gen/%.o)
$(FUZZ_DIR)/gen/%.o: $(BUILD)/gen/%.c $(LCM_GEN_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(CSTD) -g -O1 -I$(BUILD)/gen $(FUZZ_SAN) -fsanitize=fuzzer-no-link -c $< -o $@
FUZZ_LCM_SRCS := $(FUZZ_LX)/lx_lcm.c $(FUZZ_LX)/lx_err.c
$(FUZZ_DIR)/fuzz_lcm: tests/fuzz/fuzz_lcm.c $(FUZZ_LCM_SRCS) $(FUZZ_LCM_GEN_OBJS) $(CORE_SRCS) $(FUZZ_HDRS) $(LCM_GEN_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< $(FUZZ_LCM_SRCS) $(FUZZ_LCM_GEN_OBJS) $(CORE_SRCS) -o $@ $(LCM_LIBS) -lm

# The radiotap + 802.11 parser, and the replay-stream parser with the player.
$(FEED)/fuzz_radiotap: tests/fuzz/fuzz_radiotap.c $(FUZZ_LX)/lx_radiotap.c $(FUZZ_LX)/lx_radiotap.h
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=c11 -g -O1 -I$(FUZZ_LX) -fsanitize=fuzzer,address,undefined \
		-fno-sanitize-recover=all $< $(FUZZ_LX)/lx_radiotap.c -o $@
# fuzz_replay: the lattice and reachability code compares map cells and lattice bounds,
# not input bytes; built without comparison tracing (edges still counted) a control period
# costs a third (CHANGELOG.md, "Fuzzing speed").
FUZZ_FW_SRCS := firmware/rfs_app.c firmware/rfs_replay.c
FUZZ_NOCMP := common/rfs_map.c common/rfs_map_walls.c common/rfs_reach.c
FUZZ_NOCMP_OBJS := $(FUZZ_NOCMP:common/%.c=$(FW)/fuzz-nocmp/%.o)
$(FW)/fuzz-nocmp/%.o: common/%.c $(FUZZ_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=c11 -g -O1 $(INC_fw) -fsanitize=address,undefined -fno-sanitize-recover=all \
		-fsanitize=fuzzer-no-link -fno-sanitize-coverage=trace-cmp -c $< -o $@
$(FW)/fuzz_replay: tests/fuzz/fuzz_replay.c $(FUZZ_FW_SRCS) $(CORE_SRCS) $(FUZZ_NOCMP_OBJS) $(FUZZ_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=c11 -g -O1 $(INC_fw) -fsanitize=fuzzer,address,undefined \
		-fno-sanitize-recover=all $< $(FUZZ_FW_SRCS) $(filter-out $(FUZZ_NOCMP),$(CORE_SRCS)) \
		$(FUZZ_NOCMP_OBJS) -o $@

# make test: each target over its committed corpus plus a short burst of new inputs.
FUZZ_TEST_RUNS ?= 5000
$(eval $(call test_script,fuzz,tests/fuzz/run_all.sh $(BUILD) --runs $(FUZZ_TEST_RUNS) $(FUZZ_OWN),$(FUZZ_BINS)))
$(eval $(call test_script,fuzz_radiotap,tests/fuzz/run_one.sh $(FEED)/fuzz_radiotap $(FEED)/fuzz-corpus tests/fuzz/corpus/radiotap 20000,$(FEED)/fuzz_radiotap))
$(eval $(call test_script,fuzz_replay,tests/fuzz/run_one.sh $(FW)/fuzz_replay $(FW)/fuzz-corpus tests/fuzz/corpus/replay 2000,$(FW)/fuzz_replay))

# make fuzz: every target for FUZZ_SECONDS each.
FUZZ_ALL_BINS := $(FUZZ_BINS) $(FEED)/fuzz_radiotap $(FW)/fuzz_replay
FUZZ_TARGETS ?= $(FUZZ_OWN) radiotap replay
FUZZ_LONG_RUNS ?= 10000000
.PHONY: fuzz fuzz-build fuzz-long
fuzz-build: $(FUZZ_ALL_BINS)
fuzz: fuzz-build
	@tests/fuzz/run_all.sh $(BUILD) --seconds $(FUZZ_SECONDS) $(FUZZ_TARGETS)
fuzz-long: fuzz-build
	@nice -n 19 tests/fuzz/run_all.sh $(BUILD) --runs $(FUZZ_LONG_RUNS) $(FUZZ_TARGETS)
