# mk/pathloss.mk - the map-aware path-loss model (issue 10): common/rfs_pathloss.{c,h}.
# Its CMocka test (tests/common/test_pathloss.c, with the double reference
# tests/common/ref_pathloss.h) is discovered by the top Makefile.

# Instructions per relearn, per slice and per prediction (callgrind, exact), state bytes.
$(BUILD)/bin/bench_pathloss: bench/bench_pathloss.c $(HOST_LIB_DEPS) $(CORE_LIB) $(HOST_HDRS)
	@mkdir -p $(@D) $(BUILD)/obj/bench
	$(CC) $(HOST_CFLAGS) -c $< -o $(BUILD)/obj/bench/bench_pathloss.o
	$(HOST_LINK) -o $@ $(BUILD)/obj/bench/bench_pathloss.o $(HOST_LIB_DEPS) $(CORE_LIB) $(HOST_LDLIBS)

ALL_TARGETS += $(BUILD)/bin/bench_pathloss
BENCH_TARGETS += bench-pathloss

PATHLOSS_BENCH_MAP ?= scenarios/maps/office.yaml
# ir NAME ARGS...: instructions counted inside the toggled region.
define pathloss_ir
valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file=$$tmp/$(1).cg \
    $(BUILD)/bin/bench_pathloss $(PATHLOSS_BENCH_MAP) $(2) > $$tmp/$(1).out 2>/dev/null; \
callgrind_annotate $$tmp/$(1).cg 2>/dev/null | awk '/PROGRAM TOTALS/ {gsub(",","",$$1); print $$1}'
endef

.PHONY: bench-pathloss
bench-pathloss: $(BUILD)/bin/bench_pathloss
	@set -e; tmp=$$(mktemp -d); trap 'rm -rf "$$tmp"' EXIT; \
	echo "pathloss: $(PATHLOSS_BENCH_MAP), samples at random legal points, host x86-64 (callgrind, exact)"; \
	printf "  %7s %6s %11s %14s %15s %12s\n" samples bins candidates units "relearn instr" "per unit"; \
	for n in 1000 10000; do \
	    ir=$$($(call pathloss_ir,r$$n,relearn $$n)); \
	    b=$$(awk '/^bins/ {print $$2}' $$tmp/r$$n.out); c=$$(awk '/^candidates/ {print $$2}' $$tmp/r$$n.out); \
	    u=$$(awk '/^units/ {print $$2}' $$tmp/r$$n.out); \
	    printf "  %7s %6s %11s %14s %15s %12s\n" $$n $$b $$c $$u $$ir $$(awk -v a=$$ir -v u=$$u 'BEGIN{printf "%.0f", a/u}'); \
	done; \
	grep -h '^estimate\|^state_bytes\|^coarse' $$tmp/r10000.out | sed 's/^/  /'; \
	for bud in 2000 20000; do \
	    ir=$$($(call pathloss_ir,s$$bud,slice 10000 $$bud)); \
	    echo "  first slice, budget $$bud units: $$ir instructions; whole fit in $$(awk '/^calls/ {print $$2}' $$tmp/s$$bud.out) calls"; \
	done; \
	ir=$$($(call pathloss_ir,p,predict 10000)); echo "  one prediction (relearn check): $$ir instructions"
