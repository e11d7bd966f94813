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
# $(call pathloss_ir,NAME,ARGS): instructions counted inside the toggled region; the
# program's own output is left in $tmp/NAME.out.
define pathloss_ir
valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file=$$tmp/$(1).cg \
    $(BUILD)/bin/bench_pathloss $(PATHLOSS_BENCH_MAP) $(2) > $$tmp/$(1).out 2>/dev/null; \
callgrind_annotate $$tmp/$(1).cg 2>/dev/null | awk '/PROGRAM TOTALS/ {gsub(",","",$$1); print $$1}'
endef
# $(call pathloss_row,NAME,ARGS,LABEL): one table row.
define pathloss_row
ir=$$($(call pathloss_ir,$(1),$(2))); o=$$tmp/$(1).out; \
v() { awk -v k=$$1 '$$1 == k {print $$2}' $$o; }; \
printf "  %-34s %5s %5s %8s %8s %13s %9s\n" "$(3)" $$(v bins) $$(v candidates) $$(v walls_counted) \
    $$(v footprints_cached) $$ir $$(awk -v a=$$ir -v u=$$(v walls_counted) 'BEGIN{printf "%.0f", a/(u>0?u:1)}')
endef

.PHONY: bench-pathloss
bench-pathloss: $(BUILD)/bin/bench_pathloss
	@set -e; tmp=$$(mktemp -d); trap 'rm -rf "$$tmp"' EXIT; \
	echo "pathloss: $(PATHLOSS_BENCH_MAP) (core grid 0.1 m), host x86-64 instructions (callgrind, exact)"; \
	printf "  %-34s %5s %5s %8s %8s %13s %9s\n" workload bins cands counted cached "instructions" "per count"; \
	$(call pathloss_row,r1,relearn 1000,whole floor 1000 samples fresh); \
	$(call pathloss_row,r10,relearn 10000,whole floor 10000 samples fresh); \
	$(call pathloss_row,p150,path 150,walk 150 steps fresh); \
	$(call pathloss_row,w150,pathwarm 150,walk 150 steps cache warm); \
	$(call pathloss_row,p400,path 400,walk 400 steps fresh); \
	$(call pathloss_row,w400,pathwarm 400,walk 400 steps cache warm); \
	grep -h '^state_bytes\|^coarse' $$tmp/r10.out | sed 's/^/  /'; \
	for bud in 2000 20000; do \
	    ir=$$($(call pathloss_ir,s$$bud,slice 10000 $$bud)); \
	    echo "  whole floor 10000 samples: first slice of budget $$bud units: $$ir instructions; whole fit in $$(awk '/^calls/ {print $$2}' $$tmp/s$$bud.out) calls"; \
	done; \
	ir=$$($(call pathloss_ir,p,predict 10000)); echo "  one prediction (the relearn check): $$ir instructions"
