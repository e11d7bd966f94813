# The data path (issue 2 items 1, 2, 3, 5, 7): fixed point, RSSI window, sample store,
# ridge model, targets. Their CMocka tests are auto-discovered in tests/common/; this adds
# the callgrind driver and `make bench-data` (docs/PERFORMANCE.md, "data").
$(BUILD)/bin/bench_ridge: bench/bench_ridge.c $(CORE_LIB) $(CORE_HDRS)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $< -o $@ $(CORE_LIB) $(HOST_LDLIBS)

ALL_TARGETS += $(BUILD)/bin/bench_ridge
BENCH_TARGETS += bench-data
.PHONY: bench-data
bench-data: $(BUILD)/bin/bench_ridge $(BUILD)/arm/lib/librfs_core.a
	@scripts/bench_data.sh $(BUILD)
