# mk/feed.mk - the pcap feeder and writer (issue 5; docs/FEEDER.md): the radiotap parser,
# rfseek-feed, the writer, their tests against tshark, the fuzz target and bench-feed.
PCAP_LIBS := $(shell pkg-config --libs libpcap 2>/dev/null || echo -lpcap)
HOST_LDLIBS += $(PCAP_LIBS)

FEED := $(BUILD)/feed
FEED_SRCS := firmware/port/linux/lx_pcap.c firmware/port/linux/lx_radiotap.c
FEED_HDRS := firmware/port/linux/lx_pcap.h firmware/port/linux/lx_radiotap.h

# rfseek-feed under ASan+UBSan (the host and core libraries' ASan builds: --pose runs the
# simulator's controller), for the bad-input and replay tests.
# (Depends on the plain build too, so generated headers added by later fragments exist.)
$(FEED)/asan/rfseek-feed: host_sim/prog/rfseek-feed.c $(HOST_ASAN_LIB) $(CORE_ASAN_LIB) $(BUILD)/bin/rfseek-feed
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -O1 $(SAN_FLAGS) -c $< -o $(FEED)/asan/rfseek-feed.o
	$(HOST_LINK) $(SAN_FLAGS) -o $@ $(FEED)/asan/rfseek-feed.o $(HOST_ASAN_LIB) $(CORE_ASAN_LIB) $(HOST_LDLIBS)

# Writes radiotap captures through lx_pcap_writer (bench input, writer cross-check).
$(FEED)/feed_writegen: tests/feed/feed_writegen.c $(FEED_SRCS) $(FEED_HDRS)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $< $(FEED_SRCS) -o $@ $(PCAP_LIBS)

# Captures in many radiotap / 802.11 layouts (python, independent of our code) and one
# written by our writer.
$(FEED)/gen/.stamp: scripts/gen_captures.py $(FEED)/feed_writegen
	@rm -rf $(FEED)/gen && mkdir -p $(FEED)/gen
	$(PYTHON) scripts/gen_captures.py $(FEED)/gen
	$(FEED)/feed_writegen $(FEED)/gen/writer.pcap 2000 > $(FEED)/gen/writer.pcap.macs
	@touch $@

# libFuzzer target over the radiotap + 802.11 parser (clang only).
FUZZ_CC ?= clang
$(FEED)/fuzz_radiotap: tests/fuzz/fuzz_radiotap.c firmware/port/linux/lx_radiotap.c firmware/port/linux/lx_radiotap.h
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=c11 -g -O1 -Ihost_sim -fsanitize=fuzzer,address,undefined \
		-fno-sanitize-recover=all $< firmware/port/linux/lx_radiotap.c -o $@

TEST_DEPS += $(BUILD)/bin/rfseek-feed $(FEED)/asan/rfseek-feed $(FEED)/gen/.stamp $(FEED)/fuzz_radiotap
TEST_SCRIPTS += "tests/feed/cross_check.sh $(BUILD)/bin/rfseek-feed tests/data/captures/*.pcap $(FEED)/gen/*.pcap $(FEED)/gen/*.pcapng"
TEST_SCRIPTS += "tests/feed/bad_input.sh $(FEED)/asan/rfseek-feed $(FEED)/gen"
TEST_SCRIPTS += "$(PYTHON) tests/feed/replay_test.py $(FEED)/asan/rfseek-feed"
TEST_SCRIPTS += "tests/fuzz/run_one.sh $(FEED)/fuzz_radiotap $(FEED)/fuzz-corpus tests/fuzz/corpus/radiotap 20000"

# CMocka tests of our modules, linked with our sources only (not all of librfs_host.a),
# plain and under ASan+UBSan.
define feed_cmocka
$(BUILD)/tests/$(1): tests/host_sim/$(1).c $(FEED_SRCS) $(FEED_HDRS) tests/rfs_test.h
	@mkdir -p $$(@D)
	$$(CC) $$(HOST_CFLAGS) -Itests $$< $(FEED_SRCS) -o $$@ -lcmocka $(PCAP_LIBS)
$(BUILD)/asan/tests/$(1): tests/host_sim/$(1).c $(FEED_SRCS) $(FEED_HDRS) tests/rfs_test.h
	@mkdir -p $$(@D)
	$$(CC) $$(HOST_CFLAGS) -O1 $$(SAN_FLAGS) -Itests $$< $(FEED_SRCS) -o $$@ -lcmocka $(PCAP_LIBS)
TEST_BINS += $(BUILD)/tests/$(1) $(BUILD)/asan/tests/$(1)
endef
$(eval $(call feed_cmocka,test_lx_radiotap))
$(eval $(call feed_cmocka,test_lx_pcap))

# Frames/s extracting one MAC's RSSI from a 1,000,000-frame capture, side by side with
# tshark on the same file (median of 3).
BENCH_TARGETS += bench-feed
.PHONY: bench-feed
bench-feed: $(BUILD)/bin/rfseek-feed $(FEED)/feed_writegen
	@tests/feed/bench_feed.sh $(BUILD)/bin/rfseek-feed $(FEED)/feed_writegen $(FEED)/bench
