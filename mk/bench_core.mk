# The core's worst-case iteration: callgrind instructions, wall time against scikit-learn.
$(BUILD)/bin/bench_core: bench/bench_core.c $(CORE_LIB) $(CORE_HDRS)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $< -o $@ $(CORE_LIB) $(HOST_LDLIBS)

ALL_TARGETS += $(BUILD)/bin/bench_core
BENCH_TARGETS += bench-core
.PHONY: bench-core
bench-core: $(BUILD)/bin/bench_core
	@scripts/bench_core.sh $(BUILD)
