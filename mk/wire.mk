# mk/wire.mk - CAN protocol checks, SocketCAN adapter, LCM types and rfseekd (issue 4).

# --- CAN protocol: DBC checked with canmatrix against frames we encode ----------------
WIRE_VEC := $(BUILD)/tests/wire/can_vectors
$(WIRE_VEC): tests/wire/can_vectors.c $(CORE_LIB) $(CORE_HDRS)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $< -o $@ $(CORE_LIB)
TEST_DEPS += $(WIRE_VEC)
TEST_SCRIPTS += 'tests/wire/dbc_test.sh $(BUILD)'

# --- SocketCAN: the static test binary and the VM (or native vcan) test --------------
WIRE_VM_BIN := $(BUILD)/tests/vm/can_vm_test
$(WIRE_VM_BIN): tests/vm/can_vm_test.c firmware/port/linux/lx_can.c firmware/port/linux/lx_can.h $(CORE_LIB) $(CORE_HDRS)
	@mkdir -p $(@D)
	$(CC) $(CSTD) $(WARN) $(OPT) -D_DEFAULT_SOURCE -Icommon -Ihost_sim -static tests/vm/can_vm_test.c firmware/port/linux/lx_can.c $(CORE_LIB) -o $@
TEST_DEPS += $(WIRE_VM_BIN)
TEST_SCRIPTS += 'tests/vm/run_vm_test.sh $(BUILD)'

# --- LCM: types generated with lcm-gen at build time into $(BUILD)/gen ----------------
# Generated C has unused parameters: the top Makefile compiles $(BUILD)/gen/*.c without
# -Werror. pkg-config's lcm.pc needs glib's .pc files; fall back to -llcm without them.
WIRE_LCM_TYPES := $(sort $(wildcard lcm/*.lcm))
WIRE_GEN_NAMES := $(patsubst lcm/%.lcm,rfseek_%,$(WIRE_LCM_TYPES))
HOST_GEN_SRCS += $(WIRE_GEN_NAMES:%=$(BUILD)/gen/%.c)
HOST_GEN_HDRS += $(WIRE_GEN_NAMES:%=$(BUILD)/gen/%.h)
HOST_LDLIBS += $(shell pkg-config --libs lcm 2>/dev/null || echo -llcm)
$(BUILD)/gen/rfseek_%.c $(BUILD)/gen/rfseek_%.h: lcm/%.lcm
	@mkdir -p $(BUILD)/gen
	lcm-gen -c --c-cpath $(BUILD)/gen --c-hpath $(BUILD)/gen $<

# --- rfseekd and the LCM adapter: tools, tests ----------------------------------------
WIRE_LCM_TOOL := $(BUILD)/tests/wire/lcm_tool
$(WIRE_LCM_TOOL): tests/wire/lcm_tool.c $(HOST_LIB_DEPS) $(CORE_LIB) $(HOST_HDRS)
	@mkdir -p $(@D)
	$(HOST_LINK) $(HOST_CFLAGS) -x c $< -x none -o $@ $(HOST_LIB_DEPS) $(CORE_LIB) $(HOST_LDLIBS)
TEST_DEPS += $(WIRE_LCM_TOOL) $(BUILD)/bin/rfseekd $(BUILD)/bin/rfseek-sim-lcm
TEST_SCRIPTS += 'tests/wire/rfseekd_test.sh $(BUILD)'
$(eval $(call cmocka_test,test_lcm,tests/wire/test_lcm.c,))
# The receiver heartbeat (issue 10) through rfseek-record/-replay and the qemu image.
TEST_DEPS += firmware $(BUILD)/bin/rfseek-record $(BUILD)/bin/rfseek-replay
TEST_SCRIPTS += 'tests/wire/heartbeat_replay.sh $(BUILD)'
# ... and through the pcap feeder's replay (every captured frame proves the receiver alive).
TEST_DEPS += $(BUILD)/feed/asan/rfseek-feed
TEST_SCRIPTS += '$(PYTHON) tests/wire/feed_heartbeat.py $(BUILD)/feed/asan/rfseek-feed'

# --- bench: codec instructions (callgrind), two-process overhead ----------------------
$(BUILD)/tests/wire/bench_can: tests/wire/bench_can.c $(CORE_LIB) $(CORE_HDRS)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $< -o $@ $(CORE_LIB)
.PHONY: bench-wire
bench-wire: $(BUILD)/tests/wire/bench_can $(BUILD)/bin/rfseekd $(BUILD)/bin/rfseek-sim-lcm $(BUILD)/bin/rfseek-sim
	@tests/wire/bench_wire.sh $(BUILD)
BENCH_TARGETS += bench-wire

# rfseekd under ASan+UBSan, for the malformed-input replay in tests/wire/rfseekd_test.sh.
$(BUILD)/asan/bin/rfseekd: firmware/port/linux/prog/rfseekd.c $(HOST_ASAN_LIB_DEPS) $(CORE_ASAN_LIB) $(HOST_HDRS)
	@mkdir -p $(@D)
	$(HOST_LINK) $(HOST_CFLAGS) -O1 $(SAN_FLAGS) -Ifirmware -Ifirmware/port/linux -x c $< -x none -o $@ \
		$(HOST_ASAN_LIB_DEPS) $(CORE_ASAN_LIB) $(HOST_LDLIBS)
TEST_DEPS += $(BUILD)/asan/bin/rfseekd
