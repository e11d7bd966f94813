# rfseek top-level build. `make` builds everything for the host, `make test` runs every
# test, `make check T=NAME` one of them, `make firmware` cross-compiles the Cortex-M4
# image, `make bench` prints figures, `make demo` runs the default simulated mission.
# Each part of the tree has its fragment mk/<part>.mk (core, firmware, linux, sim, fuzz,
# bench, lint). Every name two fragments share is defined here, before the includes, so
# no fragment depends on the order they are read in.
.DEFAULT_GOAL := all
SHELL := /bin/bash

BUILD ?= build
CC ?= gcc
CXX ?= g++
ifeq ($(origin CC),default)
CC := gcc
endif
ifeq ($(origin CXX),default)
CXX := g++
endif
ARM_CC ?= arm-none-eabi-gcc
PYTHON ?= /usr/bin/python3

WARN := -Wall -Wextra -Werror
CSTD := -std=c11
OPT ?= -O2 -g
# Every object writes its header dependencies beside it (read back at the end of this
# file): touching a header recompiles only the objects that include it.
DEPFLAGS := -MMD -MP
SAN_FLAGS := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
HOST_CFLAGS := $(CSTD) $(WARN) $(OPT) -D_DEFAULT_SOURCE
HOST_CXXFLAGS := -std=c++17 $(WARN) $(OPT)

# --- the layers: host_sim -> firmware/port/linux -> firmware -> common ------------------
# One library per layer (and its ASan+UBSan twin); a layer's include path holds itself and
# the layers below, never above.
CORE_SRCS := $(sort $(wildcard common/*.c))
CORE_LIB := $(BUILD)/lib/librfs_core.a
CORE_ASAN_LIB := $(BUILD)/asan/lib/librfs_core.a
FW_LIB := $(BUILD)/lib/librfs_fw.a
FW_ASAN_LIB := $(BUILD)/asan/lib/librfs_fw.a
LINUX_LIB := $(BUILD)/lib/librfs_linux.a
LINUX_ASAN_LIB := $(BUILD)/asan/lib/librfs_linux.a
SIM_LIB := $(BUILD)/lib/librfs_sim.a
SIM_ASAN_LIB := $(BUILD)/asan/lib/librfs_sim.a
FW := $(BUILD)/firmware
FEED := $(BUILD)/feed
FUZZ_DIR := $(BUILD)/fuzz

INC_core := -Icommon
INC_fw := $(INC_core) -Ifirmware
INC_linux := $(INC_fw) -Ifirmware/port/linux -I$(BUILD)/gen
INC_sim := $(INC_linux) -Ihost_sim

# Outside libraries: pkg-config, or the plain -l when a .pc file is missing (lcm.pc needs
# glib's). Only the Linux port and the simulator use them; only the simulator uses Box2D.
YAML_CFLAGS := $(shell pkg-config --cflags yaml-0.1 2>/dev/null)
YAML_LIBS := $(shell pkg-config --libs yaml-0.1 2>/dev/null || echo -lyaml)
LCM_LIBS := $(shell pkg-config --libs lcm 2>/dev/null || echo -llcm)
PCAP_LIBS := $(shell pkg-config --libs libpcap 2>/dev/null || echo -lpcap)
PNG_CFLAGS := $(shell pkg-config --cflags libpng 2>/dev/null)
PNG_LIBS := $(shell pkg-config --libs libpng 2>/dev/null || echo -lpng)

LIBS_core := $(CORE_LIB)
LIBS_fw := $(FW_LIB) $(CORE_LIB)
LIBS_linux := $(LINUX_LIB) $(LIBS_fw)
LIBS_sim := $(SIM_LIB) $(LIBS_linux)
ASAN_LIBS_core := $(CORE_ASAN_LIB)
ASAN_LIBS_fw := $(FW_ASAN_LIB) $(CORE_ASAN_LIB)
ASAN_LIBS_linux := $(LINUX_ASAN_LIB) $(ASAN_LIBS_fw)
ASAN_LIBS_sim := $(SIM_ASAN_LIB) $(ASAN_LIBS_linux)
LDLIBS_core := -lm
LDLIBS_fw := -lm
LDLIBS_linux := -Wl,--as-needed $(LCM_LIBS) $(YAML_LIBS) $(PCAP_LIBS) $(PNG_LIBS) -lm
LDLIBS_sim := -lbox2d $(LCM_LIBS) $(YAML_LIBS) $(PCAP_LIBS) $(PNG_LIBS) -lm
# The C linker for everything but the simulator, whose Box2D adapter is C++.
LD_core := $(CC)
LD_fw := $(CC)
LD_linux := $(CC)
LD_sim := $(CXX)

# lcm-gen types (lcm/<type>.lcm -> $(BUILD)/gen/rfseek_<type>.{c,h}, mk/linux.mk).
LCM_GEN_NAMES := $(patsubst lcm/%.lcm,rfseek_%,$(sort $(wildcard lcm/*.lcm)))
LCM_GEN_SRCS := $(LCM_GEN_NAMES:%=$(BUILD)/gen/%.c)
LCM_GEN_HDRS := $(LCM_GEN_NAMES:%=$(BUILD)/gen/%.h)

# Lists the fragments extend.
ALL_TARGETS :=       # built by `make`
TEST_BIN_NAMES :=    # CMocka programs: build/tests/NAME and build/asan/tests/NAME
TEST_SCRIPT_NAMES := # other test commands (each prints PASS/FAIL lines)
TEST_DEPS :=         # what the test commands need built
BENCH_TARGETS :=     # phony targets run by `make bench`
CLEAN_EXTRA :=

# $(call cmocka_test,NAME,SOURCE,LAYER): build/tests/NAME and its ASan+UBSan twin
# build/asan/tests/NAME, SOURCE linked with the libraries of LAYER (core, fw, linux, sim).
define cmocka_test
$(BUILD)/tests/$(1): $(2) $$(LIBS_$(3)) | $$(LCM_GEN_HDRS)
	@mkdir -p $$(@D)
	$$(LD_$(3)) $$(HOST_CFLAGS) $$(DEPFLAGS) -MF $$@.d -MT $$@ $$(INC_$(3)) -Itests -x c $(2) -x none -o $$@ $$(LIBS_$(3)) -lcmocka $$(LDLIBS_$(3))
$(BUILD)/asan/tests/$(1): $(2) $$(ASAN_LIBS_$(3)) | $$(LCM_GEN_HDRS)
	@mkdir -p $$(@D)
	$$(LD_$(3)) $$(HOST_CFLAGS) -O1 $$(SAN_FLAGS) $$(DEPFLAGS) -MF $$@.d -MT $$@ $$(INC_$(3)) -Itests -x c $(2) -x none -o $$@ $$(ASAN_LIBS_$(3)) -lcmocka $$(LDLIBS_$(3))
TEST_BIN_NAMES += $(1)
endef

# $(call test_script,NAME,COMMAND,PREREQUISITES[,serial]): a test command run from the
# repository root by `make test` (in parallel with the others unless `serial`) and by
# `make check T=NAME`.
define test_script
TEST_SCRIPT_NAMES += $(1)
TEST_CMD_$(1) = $(2)
TEST_DEPS_$(1) = $(3)
TEST_SERIAL_$(1) := $(4)
TEST_DEPS += $(3)
endef

include mk/core.mk mk/firmware.mk mk/linux.mk mk/sim.mk mk/fuzz.mk mk/bench.mk mk/lint.mk

# --- top-level goals -------------------------------------------------------------------
.PHONY: all deps test test-only check bench demo firmware clean help
all: $(ALL_TARGETS)

help:
	@echo "make deps      install missing Debian packages (needs root)"
	@echo "make           build everything for the host into $(BUILD)/"
	@echo "make test      deps + build + every test (plain and ASan+UBSan), in parallel"
	@echo "               (TEST_JOBS=N, default nproc), logs in $(BUILD)/test-logs/, summary line last"
	@echo "make check T=NAME [CASE=GLOB] [ASAN=1]"
	@echo "               build and run one test: a CMocka program (test_seek; ASAN=1 its"
	@echo "               ASan+UBSan twin; CASE runs only the cases matching the glob) or a"
	@echo "               test script (sim_cli, rfseekd, bit_identical, ...)"
	@echo "make check-list  the names make check accepts"
	@echo "make firmware  cross-compile the Cortex-M4 image"
	@echo "make bench     print the performance figures (docs/PERFORMANCE.md)"
	@echo "make demo      deps + run the default simulated mission, figures in out/demo/"
	@echo "make lint      cppcheck, clang-tidy and the layer check"
	@echo "make fuzz      every libFuzzer target for FUZZ_SECONDS each"
	@echo "make fuzz-long every libFuzzer target for FUZZ_LONG_RUNS (10 M) executions, niced"
	@echo "make sweep     the simulator under ASan+UBSan over SWEEP_SEEDS seeds"

deps:
	@scripts/deps.sh

test: deps
	@$(MAKE) --no-print-directory test-only

# The job list scripts/run_tests.sh reads: NAME, kind (bin or script), serial or not,
# command; one per line ("-" for an empty field).
TAB := $(shell printf '\t')
define NEWLINE


endef
TEST_JOBS_TEXT = $(foreach n,$(TEST_BIN_NAMES),$(n)$(TAB)bin$(TAB)-$(TAB)$(BUILD)/tests/$(n)$(NEWLINE)asan/$(n)$(TAB)bin$(TAB)-$(TAB)$(BUILD)/asan/tests/$(n)$(NEWLINE))$(foreach s,$(TEST_SCRIPT_NAMES),$(s)$(TAB)script$(TAB)$(or $(TEST_SERIAL_$(s)),-)$(TAB)$(TEST_CMD_$(s))$(NEWLINE))
TEST_BINS = $(TEST_BIN_NAMES:%=$(BUILD)/tests/%) $(TEST_BIN_NAMES:%=$(BUILD)/asan/tests/%)

test-only: all $(TEST_BINS) $(TEST_DEPS)
	$(shell mkdir -p $(BUILD))$(file >$(BUILD)/test-jobs.tsv,$(TEST_JOBS_TEXT))
	@BUILD=$(BUILD) scripts/run_tests.sh $(BUILD)/test-jobs.tsv

# make check T=NAME: only what that test needs is built.
CHECK_NAME = $(if $(filter $(T),$(TEST_BIN_NAMES)),$(if $(ASAN),asan/)$(T),$(T))
CHECK_PREREQS = $(if $(filter $(T),$(TEST_BIN_NAMES)),$(BUILD)/$(if $(ASAN),asan/)tests/$(T),$(TEST_DEPS_$(T)))
check: $(if $(T),$(CHECK_PREREQS))
	@if [ -z "$(T)" ]; then echo "make check T=NAME [CASE=GLOB] [ASAN=1]; names: make check-list" >&2; exit 2; fi
	@if [ -z "$(filter $(T),$(TEST_BIN_NAMES) $(TEST_SCRIPT_NAMES))" ]; then \
	    echo "make check: no test named '$(T)' (make check-list)" >&2; exit 2; fi
	$(shell mkdir -p $(BUILD))$(file >$(BUILD)/test-jobs.tsv,$(TEST_JOBS_TEXT))
	@BUILD=$(BUILD) RFS_TEST_CASE='$(CASE)' scripts/run_tests.sh $(BUILD)/test-jobs.tsv --only '$(CHECK_NAME)'

.PHONY: check-list
check-list:
	@echo "CMocka programs: $(sort $(TEST_BIN_NAMES))"
	@echo "test scripts:    $(sort $(TEST_SCRIPT_NAMES))"

bench: all $(BENCH_TARGETS)

clean:
	rm -rf $(BUILD) $(CLEAN_EXTRA)

# Header dependencies written by $(DEPFLAGS) (none before the first build).
-include $(shell find $(BUILD) \( -path '$(BUILD)/fuzz' -o -path '$(BUILD)/vm' -o -name 'fuzz-corpus' \
	-o -path '$(BUILD)/test-logs' \) -prune -o -name '*.d' -print 2>/dev/null)
