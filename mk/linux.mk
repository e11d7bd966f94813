# mk/linux.mk - the Linux port (firmware/port/linux/): its I/O adapters (SocketCAN, LCM,
# map files with PGM and PNG images, YAML, pcap, radiotap, one-line errors) and the
# lcm-gen types as librfs_linux.a, C only; rfseekd and rfseek-replay linked with the C
# linker against it, the application and the core only; their tests, the SocketCAN VM
# test and the link check.
LINUX_SRCS := $(sort $(wildcard firmware/port/linux/*.c))
LINUX_CFLAGS := $(HOST_CFLAGS) $(INC_linux) $(YAML_CFLAGS) $(PNG_CFLAGS)
LINUX_PROGS := $(patsubst firmware/port/linux/prog/%.c,$(BUILD)/bin/%,$(sort $(wildcard firmware/port/linux/prog/*.c)))

# lcm-gen C has unused parameters: compiled without -Werror.
$(BUILD)/gen/rfseek_%.c $(BUILD)/gen/rfseek_%.h: lcm/%.lcm
	@mkdir -p $(BUILD)/gen
	lcm-gen -c --c-cpath $(BUILD)/gen --c-hpath $(BUILD)/gen $<
# The same types for Python (scripts/lcm_log.py): one package, rfseek, needing only struct.
LCM_PY_INIT := $(BUILD)/gen/python/rfseek/__init__.py
$(LCM_PY_INIT): $(sort $(wildcard lcm/*.lcm))
	@rm -rf $(BUILD)/gen/python/rfseek && mkdir -p $(BUILD)/gen/python
	lcm-gen -p --ppath $(BUILD)/gen/python $^
$(BUILD)/gen/%.o: $(BUILD)/gen/%.c
	$(CC) $(CSTD) $(OPT) -D_DEFAULT_SOURCE -I$(BUILD)/gen $(DEPFLAGS) -c $< -o $@
$(BUILD)/gen/%.asan.o: $(BUILD)/gen/%.c
	$(CC) $(CSTD) -O1 -g $(SAN_FLAGS) -D_DEFAULT_SOURCE -I$(BUILD)/gen $(DEPFLAGS) -c $< -o $@

# The adapters and the programs' mains (prog/); every object waits for the generated
# headers, which lx_lcm.c and some tests include.
$(BUILD)/obj/firmware/port/linux/%.o: firmware/port/linux/%.c | $(LCM_GEN_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LINUX_CFLAGS) $(DEPFLAGS) -c $< -o $@
$(BUILD)/asan/obj/firmware/port/linux/%.o: firmware/port/linux/%.c | $(LCM_GEN_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LINUX_CFLAGS) -O1 $(SAN_FLAGS) $(DEPFLAGS) -c $< -o $@

$(LINUX_LIB): $(LINUX_SRCS:%.c=$(BUILD)/obj/%.o) $(LCM_GEN_SRCS:%.c=%.o)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^
$(LINUX_ASAN_LIB): $(LINUX_SRCS:%.c=$(BUILD)/asan/obj/%.o) $(LCM_GEN_SRCS:%.c=%.asan.o)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^

$(LINUX_PROGS): $(BUILD)/bin/%: $(BUILD)/obj/firmware/port/linux/prog/%.o $(LIBS_linux)
	@mkdir -p $(@D)
	$(LD_linux) -o $@ $< $(LIBS_linux) $(LDLIBS_linux)
# rfseekd under ASan+UBSan, for the malformed-input replay in tests/wire/rfseekd_test.sh.
$(BUILD)/asan/bin/rfseekd: $(BUILD)/asan/obj/firmware/port/linux/prog/rfseekd.o $(ASAN_LIBS_linux)
	@mkdir -p $(@D)
	$(LD_linux) $(SAN_FLAGS) -o $@ $< $(ASAN_LIBS_linux) $(LDLIBS_linux)

ALL_TARGETS += $(LINUX_LIB) $(LINUX_PROGS) $(LCM_PY_INIT)

# --- tests -------------------------------------------------------------------------------
# The map loader on real maps (scenarios/maps) and bad input (tests/data/maps_bad/);
# the radiotap parser and the pcap writer against tshark; the live feed's heartbeat times;
# candump -L lines against can-utils' log2long; the LCM adapter and the path-loss estimate
# in the seeker status (hand-decoded bytes).
$(eval $(call cmocka_test,test_lx_map,tests/linux/test_lx_map.c,linux))
$(eval $(call cmocka_test,test_lx_radiotap,tests/linux/test_lx_radiotap.c,linux))
$(eval $(call cmocka_test,test_lx_pcap,tests/linux/test_lx_pcap.c,linux))
$(eval $(call cmocka_test,test_lx_feed,tests/linux/test_lx_feed.c,linux))
$(eval $(call cmocka_test,test_lx_candump,tests/linux/test_lx_candump.c,linux))
$(eval $(call cmocka_test,test_lcm,tests/wire/test_lcm.c,linux))
$(eval $(call cmocka_test,test_status_est,tests/host_sim/test_status_est.c,linux))

# map_dump: a map's occupancy values and cells as lx_map reads them (tests/linux/map_formats.py,
# run from mk/sim.mk with rfseek-map).
MAP_DUMP := $(BUILD)/tests/map_dump
$(MAP_DUMP): tests/linux/map_dump.c $(LIBS_linux) | $(LCM_GEN_HDRS)
	@mkdir -p $(@D)
	$(LD_linux) $(LINUX_CFLAGS) $(DEPFLAGS) -MF $@.d -MT $@ $< -o $@ $(LIBS_linux) $(LDLIBS_linux)

# rfseekd: options, bad input, deterministic replay (also under ASan+UBSan), logs readable
# by lcm-logplayer, the two-process run with the simulator (udpm in a network namespace).
WIRE_LCM_TOOL := $(BUILD)/tests/wire/lcm_tool
$(WIRE_LCM_TOOL): tests/wire/lcm_tool.c $(LIBS_linux) | $(LCM_GEN_HDRS)
	@mkdir -p $(@D)
	$(LD_linux) $(LINUX_CFLAGS) $(DEPFLAGS) -MF $@.d -MT $@ $< -o $@ $(LIBS_linux) $(LDLIBS_linux)
$(eval $(call test_script,rfseekd,tests/wire/rfseekd_test.sh $(BUILD),$(WIRE_LCM_TOOL) $(BUILD)/bin/rfseekd $(BUILD)/asan/bin/rfseekd $(BUILD)/bin/rfseek-sim-lcm))
# LCM for users (docs/CAN.md, "Running on a robot"): scripts/lcm_log.py on rfseekd's logs
# against lcm_tool, --decisions and the CAN frames; damaged logs; scripts/lcm_route.sh and
# a two-namespace run over veth with lcm-logger beside it (network namespaces, as root).
$(eval $(call test_script,lcm_user,$(PYTHON) tests/wire/lcm_user_test.py $(BUILD),$(WIRE_LCM_TOOL) $(BUILD)/bin/rfseekd $(BUILD)/bin/rfseek-sim-lcm $(LCM_PY_INIT)))
# CAN logs (candump -L): rfseek-record's and rfseekd's through log2asc, asc2log and canmatrix,
# and replayed by rfseek-replay to the output of the recorded stream.
$(eval $(call test_script,candump,tests/wire/candump_test.sh $(BUILD),$(WIRE_LCM_TOOL) $(BUILD)/bin/rfseekd $(BUILD)/bin/rfseek-replay $(BUILD)/bin/rfseek-record))
$(eval $(call test_script,outputs,tests/wire/outputs_test.sh $(BUILD),$(WIRE_LCM_TOOL) $(BUILD)/bin/rfseekd $(BUILD)/bin/rfseek-replay $(BUILD)/bin/rfseek-record $(BUILD)/bin/rfseek-map $(BUILD)/bin/rfseek-feed))

# SocketCAN against the kernel's CAN stack: a static test binary, run natively in a network
# namespace with vcan or in a one-CPU qemu VM (its own namespace and build/vm: parallel-safe).
WIRE_VM_BIN := $(BUILD)/tests/vm/can_vm_test
WIRE_VM_OBJS := $(BUILD)/obj/firmware/port/linux/lx_can.o $(BUILD)/obj/firmware/port/linux/lx_candump.o
$(WIRE_VM_BIN): tests/vm/can_vm_test.c $(WIRE_VM_OBJS) $(CORE_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(INC_linux) $(DEPFLAGS) -MF $@.d -MT $@ -static $< $(WIRE_VM_OBJS) $(CORE_LIB) -o $@
$(eval $(call test_script,can_vm,tests/vm/run_vm_test.sh $(BUILD),$(WIRE_VM_BIN) $(BUILD)/bin/rfseekd $(BUILD)/bin/rfseek-sim-lcm))
# The live 802.11 feed end to end in the same kind of VM: mac80211_hwsim radios, hostapd,
# rfseek-feed --live --lcm -> rfseekd -> vcan0, the dBm values against tshark on the host.
$(eval $(call test_script,wifi_vm,tests/vm/run_wifi_vm_test.sh $(BUILD),$(BUILD)/bin/rfseek-feed $(BUILD)/bin/rfseekd $(WIRE_LCM_TOOL) $(LCM_PY_INIT)))

# The daemon and the player link neither Box2D nor the C++ runtime.
$(eval $(call test_script,link,scripts/check_link.sh $(LINUX_PROGS),$(LINUX_PROGS)))
