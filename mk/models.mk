# Internal models (issue 8): MLP, k-/radius-neighbours, the model registry and the
# packet-delivery-ratio target. Their CMocka tests (tests/common/test_{mlp,knn,pdr,models}.c)
# are discovered by the top Makefile; test_knn runs scikit-learn through /usr/bin/python3
# and test_pdr runs tshark, both from the repository root.

# Instruction counts per full relearn, per grid search and per fit slice (callgrind).
$(BUILD)/bin/bench_models: bench/bench_models.c $(CORE_LIB) $(CORE_HDRS)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $< -o $@ $(CORE_LIB) $(HOST_LDLIBS)

ALL_TARGETS += $(BUILD)/bin/bench_models
BENCH_TARGETS += bench-models
.PHONY: bench-models
bench-models: $(BUILD)/bin/bench_models
	@scripts/bench_models.sh $(BUILD)
