# mk/map.mk - the map loader (firmware/port/linux/lx_map.c: libyaml), its tests and rfseek-map.
HOST_CFLAGS += $(shell pkg-config --cflags yaml-0.1)
HOST_LDLIBS += $(shell pkg-config --libs yaml-0.1)

# CMocka tests of the host map loader (real maps in /work/shared/data/maps,
# bad-input fixtures in tests/data/maps_bad/).
ifneq ($(wildcard tests/linux/test_lx_map.c),)
$(eval $(call cmocka_test,test_lx_map,tests/linux/test_lx_map.c,))
endif

# rfseek-map on a real map and on bad input: one error line, non-zero exit.
ifneq ($(wildcard tests/host_sim/test_rfseek_map.sh),)
TEST_SCRIPTS += 'tests/host_sim/test_rfseek_map.sh $(BUILD)/bin/rfseek-map'
endif

# `make bench`: planner and legal-grid figures on the office scenario map and on the
# Intel lab (docs/PERFORMANCE.md, section "Map, planner, drive").
.PHONY: bench-map
bench-map: $(BUILD)/bin/rfseek-map
	@for m in scenarios/maps/office.yaml /work/shared/data/maps/intel.yaml; do \
	    if [ -e $$m ]; then $(BUILD)/bin/rfseek-map $$m --bench 200 | grep -E '^(map|core grid|lattice|bench|  )'; fi; done
BENCH_TARGETS += bench-map
