# mk/sim.mk - the simulator (host_sim/): Box2D world, radio model, scenarios, faults,
# controller, as librfs_sim.a (on top of the Linux port's librfs_linux.a); its programs
# (host_sim/prog/: rfseek-sim, rfseek-sim-lcm, rfseek-feed, rfseek-map, rfseek-record),
# their tests, the pcap feeder's tests, `make demo`, `make maps` and `make sweep`
# (docs/SIMULATOR.md, docs/FEEDER.md, docs/FAULTS.md).
SIM_SRCS := $(sort $(wildcard host_sim/*.c))
SIM_CXX_SRCS := $(sort $(wildcard host_sim/*.cpp))
SIM_CFLAGS := $(HOST_CFLAGS) $(INC_sim)
SIM_CXXFLAGS := $(HOST_CXXFLAGS) $(INC_sim)
SIM_PROGS := $(patsubst host_sim/prog/%.c,$(BUILD)/bin/%,$(sort $(wildcard host_sim/prog/*.c)))

$(BUILD)/obj/host_sim/%.o: host_sim/%.c | $(LCM_GEN_HDRS)
	@mkdir -p $(@D)
	$(CC) $(SIM_CFLAGS) $(DEPFLAGS) -c $< -o $@
$(BUILD)/obj/host_sim/%.o: host_sim/%.cpp
	@mkdir -p $(@D)
	$(CXX) $(SIM_CXXFLAGS) $(DEPFLAGS) -c $< -o $@
$(BUILD)/asan/obj/host_sim/%.o: host_sim/%.c | $(LCM_GEN_HDRS)
	@mkdir -p $(@D)
	$(CC) $(SIM_CFLAGS) -O1 $(SAN_FLAGS) $(DEPFLAGS) -c $< -o $@
$(BUILD)/asan/obj/host_sim/%.o: host_sim/%.cpp
	@mkdir -p $(@D)
	$(CXX) $(SIM_CXXFLAGS) -O1 $(SAN_FLAGS) $(DEPFLAGS) -c $< -o $@

$(SIM_LIB): $(SIM_SRCS:%.c=$(BUILD)/obj/%.o) $(SIM_CXX_SRCS:%.cpp=$(BUILD)/obj/%.o)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^
$(SIM_ASAN_LIB): $(SIM_SRCS:%.c=$(BUILD)/asan/obj/%.o) $(SIM_CXX_SRCS:%.cpp=$(BUILD)/asan/obj/%.o)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^

# Programs link with g++: the Box2D adapter is C++.
$(SIM_PROGS): $(BUILD)/bin/%: $(BUILD)/obj/host_sim/prog/%.o $(LIBS_sim)
	@mkdir -p $(@D)
	$(LD_sim) -o $@ $< $(LIBS_sim) $(LDLIBS_sim)
# rfseek-sim and rfseek-feed under ASan+UBSan (the sweep; the feeder's bad-input and replay
# tests, whose --pose runs the simulator's controller).
SWEEP_SIM := $(BUILD)/asan/bin/rfseek-sim
FEED_ASAN := $(FEED)/asan/rfseek-feed
$(SWEEP_SIM): $(BUILD)/asan/obj/host_sim/prog/rfseek-sim.o $(ASAN_LIBS_sim)
	@mkdir -p $(@D)
	$(LD_sim) $(SAN_FLAGS) -o $@ $< $(ASAN_LIBS_sim) $(LDLIBS_sim)
$(FEED_ASAN): $(BUILD)/asan/obj/host_sim/prog/rfseek-feed.o $(ASAN_LIBS_sim)
	@mkdir -p $(@D)
	$(LD_sim) $(SAN_FLAGS) -o $@ $< $(ASAN_LIBS_sim) $(LDLIBS_sim)

ALL_TARGETS += $(SIM_LIB) $(SIM_PROGS)

# --- tests of the simulator --------------------------------------------------------------
$(eval $(call cmocka_test,test_radio,tests/host_sim/test_radio.c,sim))
$(eval $(call cmocka_test,test_box2d,tests/host_sim/test_box2d.c,sim))
$(eval $(call cmocka_test,test_sim,tests/host_sim/test_sim.c,sim))
$(eval $(call cmocka_test,test_fmt,tests/host_sim/test_fmt.c,sim))
# The fault hooks alone and whole runs of the open-hall fault scenarios, log read back.
$(eval $(call cmocka_test,test_faults,tests/host_sim/test_faults.c,sim))

SIM := $(BUILD)/bin/rfseek-sim
# rfseek-sim on good and bad scenarios; on every fault scenario for 3 seeds and bad
# `faults:` sections; every strategy's options; the path-loss estimate in log.tsv,
# summary.json and residual.tsv; rfseek-map on a real map and on bad input.
$(eval $(call test_script,sim_cli,tests/host_sim/sim_cli.sh $(SIM),$(SIM)))
$(eval $(call test_script,batch_out,tests/host_sim/batch_out.sh $(SIM),$(SIM)))
# Drawn placements (--placements) against scipy's Dijkstra over the map image, their
# batches, job list and resume, bad options.
$(eval $(call test_script,placements,$(PYTHON) tests/host_sim/placements.py $(SIM),$(SIM)))
$(eval $(call test_script,greedy_extrap,$(PYTHON) tests/host_sim/greedy_extrap_check.py $(SIM),$(SIM) scripts/greedy_extrap.py))
$(eval $(call test_script,faults,tests/host_sim/faults.sh $(SIM) 3,$(SIM)))
$(eval $(call test_script,strategy_cli,tests/host_sim/strategy_cli.sh $(SIM),$(SIM)))
# A path-valued option given an option as its value, in every program (lx_err_path_opt).
$(eval $(call test_script,path_opts,tests/linux/path_opts.sh $(BUILD),$(SIM) $(BUILD)/bin/rfseek-sim-lcm $(BUILD)/bin/rfseekd $(BUILD)/bin/rfseek-feed $(BUILD)/bin/rfseek-record $(BUILD)/bin/rfseek-replay $(BUILD)/bin/rfseek-map))
# Every program in scripts/ answers --help (exit 0, a usage text, nothing written).
$(eval $(call test_script,scripts_help,tests/host_sim/scripts_help.sh $(PYTHON),))
# bridge_bounds.py's tolerance reference against a brute-force walk of the grid.
$(eval $(call test_script,bridge_bounds,$(PYTHON) tests/host_sim/bridge_bounds_check.py,))
$(eval $(call test_script,pathloss_out,tests/host_sim/pathloss_out.sh $(SIM),$(SIM)))
$(eval $(call test_script,rfseek_map,tests/host_sim/test_rfseek_map.sh $(BUILD)/bin/rfseek-map,$(BUILD)/bin/rfseek-map))
# Map images as map_server reads them: PNG of every colour type and depth, PGM, the three
# modes and negate against a reference in exact arithmetic; damaged PNGs; memory.
$(eval $(call test_script,map_formats,$(PYTHON) tests/linux/map_formats.py $(BUILD),$(MAP_DUMP) $(BUILD)/bin/rfseek-map))
# rfseek-map --mcu against firmware/rfs_app.h's limits and scripts/map2c.py, --crop keeping
# every world point's cell, --png's size and metre grid (decoded with PIL).
$(eval $(call test_script,map_tools,$(PYTHON) tests/host_sim/map_tools.py $(BUILD)/bin/rfseek-map,$(BUILD)/bin/rfseek-map))
# scripts/plot_run.py --animate: frame count, size and the robot's pixels of a short run's
# GIF decoded with Pillow; MP4 when ffmpeg is installed; bad input.
$(eval $(call test_script,animate,$(PYTHON) tests/host_sim/animate_test.py $(SIM),$(SIM)))
# The README's path from a PNG map and a capture to a run and a video, as written there.
$(eval $(call test_script,readme_path,tests/host_sim/readme_path.sh $(BUILD),$(SIM) $(BUILD)/bin/rfseek-map $(BUILD)/bin/rfseek-feed))
# rfseekd --model pathloss fills the estimate in its status (two-process run in a netns).
$(eval $(call test_script,status_est,tests/host_sim/status_est.sh $(BUILD),$(BUILD)/bin/rfseekd $(BUILD)/bin/rfseek-sim-lcm))
# Every program's model and target options and scenario keys, good and bad values; PDR
# seeking in the simulator and PDR replay of real captures against tshark; the MLP
# bit-identical on the emulated Cortex-M4 (docs/MODELS.md, "Choosing a model").
$(eval $(call test_script,models_cli,tests/host_sim/test_models_cli.sh $(BUILD),$(SIM) $(BUILD)/bin/rfseek-feed $(FEED_ASAN) $(BUILD)/bin/rfseekd $(BUILD)/bin/rfseek-record $(BUILD)/bin/rfseek-replay $(FW_IMAGES) $(WIRE_LCM_TOOL)))
# The receiver heartbeat through rfseek-record/-replay and the emulator image, and through
# the pcap feeder's replay (every captured frame proves the receiver alive).
$(eval $(call test_script,heartbeat_replay,tests/wire/heartbeat_replay.sh $(BUILD),$(BUILD)/bin/rfseek-record $(BUILD)/bin/rfseek-replay $(FW_IMAGES) $(WIRE_LCM_TOOL)))
$(eval $(call test_script,feed_heartbeat,$(PYTHON) tests/wire/feed_heartbeat.py $(FEED_ASAN),$(FEED_ASAN)))
# The simulator under ASan+UBSan, 3 seeds of the default and three fault scenarios.
$(eval $(call test_script,sweep,scripts/san_sweep.sh $(SWEEP_SIM) 3 scenarios/default.yaml scenarios/faults/office-kidnap.yaml scenarios/faults/office-rssi_silence.yaml scenarios/faults/office-bus_off.yaml,$(SWEEP_SIM)))

# --- the pcap feeder (rfseek-feed) ---------------------------------------------------------
# Captures in many radiotap / 802.11 layouts (python, independent of our code) and one
# written by our writer (lx_pcap_writer).
$(FEED)/feed_writegen: tests/feed/feed_writegen.c $(LIBS_linux)
	@mkdir -p $(@D)
	$(LD_linux) $(HOST_CFLAGS) $(INC_linux) $(DEPFLAGS) -MF $@.d -MT $@ $< -o $@ $(LIBS_linux) $(LDLIBS_linux)
# The floor bench-feed compares with: read and count every record, parse nothing.
$(FEED)/feed_count: tests/feed/feed_count.c $(LIBS_linux)
	@mkdir -p $(@D)
	$(LD_linux) $(HOST_CFLAGS) $(INC_linux) $(DEPFLAGS) -MF $@.d -MT $@ $< -o $@ $(LIBS_linux) $(LDLIBS_linux)
ALL_TARGETS += $(FEED)/feed_count
$(FEED)/gen/.stamp: scripts/gen_captures.py $(FEED)/feed_writegen
	@rm -rf $(FEED)/gen && mkdir -p $(FEED)/gen
	$(PYTHON) scripts/gen_captures.py $(FEED)/gen
	$(FEED)/feed_writegen $(FEED)/gen/writer.pcap 2000 > $(FEED)/gen/writer.pcap.macs
	@touch $@
$(eval $(call test_script,feed_cross_check,tests/feed/cross_check.sh $(BUILD)/bin/rfseek-feed tests/data/captures/*.pcap $(FEED)/gen/*.pcap $(FEED)/gen/*.pcapng,$(BUILD)/bin/rfseek-feed $(FEED)/gen/.stamp))
# --list (the survey) against tshark's own fields, aggregated per wlan.ta; a --mac that sent
# nothing: a warning and exit 3.
$(eval $(call test_script,feed_survey,$(PYTHON) tests/feed/survey_test.py $(FEED_ASAN) tests/data/captures/*.pcap tests/data/captures/malformed/*.pcap $(FEED)/gen/*.pcap $(FEED)/gen/*.pcapng $(FEED)/gen/bad/radiotap_lies.pcap,$(FEED_ASAN) $(FEED)/gen/.stamp))
$(eval $(call test_script,feed_bad_input,tests/feed/bad_input.sh $(FEED_ASAN) $(FEED)/gen,$(FEED_ASAN) $(FEED)/gen/.stamp))
$(eval $(call test_script,feed_replay,$(PYTHON) tests/feed/replay_test.py $(FEED_ASAN),$(FEED_ASAN)))

# --- goals ---------------------------------------------------------------------------------
# Scenario maps are generated by scripts/make_maps.py and committed; `make maps` redoes it.
.PHONY: maps demo sweep
maps:
	$(PYTHON) scripts/make_maps.py scenarios/maps

# The default scenario with the paper's figures (figures 2 to 4) in out/demo/.
demo: deps
	@$(MAKE) --no-print-directory BUILD=$(BUILD) $(SIM)
	BUILD=$(BUILD) scripts/demo.sh out/demo

# The simulator under ASan+UBSan over many seeds: zero sanitizer reports allowed
# (docs/RELIABILITY.md). Faults enabled: the office with each fault of scenarios/faults/.
#   make sweep [SWEEP_SEEDS=200] [SWEEP_SCENARIOS="scenarios/default.yaml ..."]
SWEEP_SEEDS ?= 200
SWEEP_SCENARIOS ?= scenarios/default.yaml $(sort $(wildcard scenarios/faults/office-*.yaml))
sweep: $(SWEEP_SIM)
	@scripts/san_sweep.sh $(SWEEP_SIM) $(SWEEP_SEEDS) $(SWEEP_SCENARIOS)
