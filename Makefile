# rfseek top-level build. `make` builds everything for the host, `make test` runs every
# test, `make firmware` cross-compiles the Cortex-M4 image, `make bench` prints figures,
# `make demo` runs the default simulated mission. Each part of the tree adds its own
# rules in mk/<part>.mk through the variables below.
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
# The core: freestanding C11, no float, no libc beyond memcpy/memset/memmove.
CORE_FLAGS := $(CSTD) $(WARN) -ffreestanding -fno-builtin -fno-common -Icommon
HOST_CFLAGS := $(CSTD) $(WARN) $(OPT) -D_DEFAULT_SOURCE -Icommon -Ihost_sim -I$(BUILD)/gen
HOST_CXXFLAGS := -std=c++17 $(WARN) $(OPT) -Icommon -Ihost_sim -I$(BUILD)/gen
HOST_LDLIBS := -lm
SAN_FLAGS := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer

# Lists the fragments extend.
ALL_TARGETS :=       # built by `make`
TEST_BINS :=         # CMocka binaries run by `make test` (ASan+UBSan variants included)
TEST_SCRIPTS :=      # other test commands run by `make test`, each prints PASS/FAIL lines
BENCH_TARGETS :=     # phony targets run by `make bench`
CLEAN_EXTRA :=

# --- the portable core ---------------------------------------------------------------
CORE_SRCS := $(sort $(wildcard common/*.c))
CORE_HDRS := $(wildcard common/*.h)
CORE_OBJS := $(CORE_SRCS:%.c=$(BUILD)/obj/%.o)
CORE_LIB := $(BUILD)/lib/librfs_core.a
CORE_ASAN_LIB := $(BUILD)/asan/lib/librfs_core.a

$(BUILD)/obj/common/%.o: common/%.c $(CORE_HDRS)
	@mkdir -p $(@D)
	$(CC) $(CORE_FLAGS) $(OPT) -c $< -o $@

$(BUILD)/asan/obj/common/%.o: common/%.c $(CORE_HDRS)
	@mkdir -p $(@D)
	$(CC) $(CORE_FLAGS) -O1 -g $(SAN_FLAGS) -c $< -o $@

$(CORE_LIB): $(CORE_OBJS)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^

$(CORE_ASAN_LIB): $(CORE_SRCS:%.c=$(BUILD)/asan/obj/%.o)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^

# The core must also build for -m32 and for the Cortex-M4, and reference nothing
# outside itself but memcpy/memset/memmove.
$(BUILD)/m32/obj/common/%.o: common/%.c $(CORE_HDRS)
	@mkdir -p $(@D)
	$(CC) -m32 $(CORE_FLAGS) -O2 -c $< -o $@

$(BUILD)/arm/obj/common/%.o: common/%.c $(CORE_HDRS)
	@mkdir -p $(@D)
	$(ARM_CC) -mcpu=cortex-m4 -mthumb -mfloat-abi=soft $(CORE_FLAGS) -Os -ffunction-sections -fdata-sections -c $< -o $@

$(BUILD)/m32/lib/librfs_core.a: $(CORE_SRCS:%.c=$(BUILD)/m32/obj/%.o)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^

$(BUILD)/arm/lib/librfs_core.a: $(CORE_SRCS:%.c=$(BUILD)/arm/obj/%.o)
	@mkdir -p $(@D)
	rm -f $@ && arm-none-eabi-ar rcs $@ $^

.PHONY: check-core
check-core: $(CORE_LIB) $(BUILD)/m32/lib/librfs_core.a $(BUILD)/arm/lib/librfs_core.a
	@scripts/check_core_symbols.sh nm $(CORE_LIB)
	@scripts/check_core_symbols.sh nm $(BUILD)/m32/lib/librfs_core.a
	@scripts/check_core_symbols.sh arm-none-eabi-nm $(BUILD)/arm/lib/librfs_core.a

ALL_TARGETS += $(CORE_LIB)

# --- CMocka tests of the core: tests/common/test_<module>.c ------------------------
# Tests include their fixtures and double-precision references (tests/*/*.h).
TEST_HDRS := $(wildcard tests/*/*.h)
# $(call cmocka_test,NAME,SOURCES,EXTRA_LIBS) defines build/tests/NAME and its ASan twin.
define cmocka_test
$(BUILD)/tests/$(1): $(2) $$(CORE_LIB) $$(HOST_LIB_DEPS) tests/rfs_test.h $$(TEST_HDRS)
	@mkdir -p $$(@D)
	$$(HOST_LINK) $$(HOST_CFLAGS) -x c -Itests $(2) -x none -o $$@ $$(HOST_LIB_DEPS) $$(CORE_LIB) -lcmocka $(3) $$(HOST_LDLIBS)
$(BUILD)/asan/tests/$(1): $(2) $$(CORE_ASAN_LIB) $$(HOST_ASAN_LIB_DEPS) tests/rfs_test.h $$(TEST_HDRS)
	@mkdir -p $$(@D)
	$$(HOST_LINK) $$(HOST_CFLAGS) -O1 $$(SAN_FLAGS) -x c -Itests $(2) -x none -o $$@ $$(HOST_ASAN_LIB_DEPS) $$(CORE_ASAN_LIB) -lcmocka $(3) $$(HOST_LDLIBS)
TEST_BINS += $(BUILD)/tests/$(1) $(BUILD)/asan/tests/$(1)
endef

# --- host-side library and programs ---------------------------------------------------
# Every host_sim/*.c and *.cpp is in librfs_host.a; host_sim/prog/<name>.c and
# firmware/port/linux/prog/<name>.c become build/bin/<name>. Fragments add flags and
# libraries (pkg-config) to HOST_CFLAGS / HOST_LDLIBS and generated sources to HOST_GEN.
HOST_SRCS := $(sort $(wildcard host_sim/*.c))
HOST_CXX_SRCS := $(sort $(wildcard host_sim/*.cpp))
HOST_HDRS = $(wildcard host_sim/*.h) $(CORE_HDRS) $(HOST_GEN_HDRS)
HOST_GEN_HDRS :=
HOST_GEN_SRCS :=
HOST_LIB := $(BUILD)/lib/librfs_host.a
HOST_ASAN_LIB := $(BUILD)/asan/lib/librfs_host.a
HOST_LIB_DEPS = $(if $(HOST_SRCS)$(HOST_CXX_SRCS),$(HOST_LIB))
HOST_ASAN_LIB_DEPS = $(if $(HOST_SRCS)$(HOST_CXX_SRCS),$(HOST_ASAN_LIB))
HOST_PROGS := $(patsubst %.c,$(BUILD)/bin/%,$(notdir $(wildcard host_sim/prog/*.c firmware/port/linux/prog/*.c)))

include $(sort $(wildcard mk/*.mk))

HOST_OBJS = $(HOST_SRCS:%.c=$(BUILD)/obj/%.o) $(HOST_CXX_SRCS:%.cpp=$(BUILD)/obj/%.o) $(HOST_GEN_SRCS:%.c=%.o)
HOST_ASAN_OBJS = $(HOST_SRCS:%.c=$(BUILD)/asan/obj/%.o) $(HOST_CXX_SRCS:%.cpp=$(BUILD)/asan/obj/%.o) $(HOST_GEN_SRCS:%.c=%.asan.o)

$(BUILD)/obj/host_sim/%.o: host_sim/%.c $(HOST_HDRS)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -c $< -o $@
$(BUILD)/obj/host_sim/%.o: host_sim/%.cpp $(HOST_HDRS)
	@mkdir -p $(@D)
	$(CXX) $(HOST_CXXFLAGS) -c $< -o $@
$(BUILD)/asan/obj/host_sim/%.o: host_sim/%.c $(HOST_HDRS)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -O1 $(SAN_FLAGS) -c $< -o $@
$(BUILD)/asan/obj/host_sim/%.o: host_sim/%.cpp $(HOST_HDRS)
	@mkdir -p $(@D)
	$(CXX) $(HOST_CXXFLAGS) -O1 $(SAN_FLAGS) -c $< -o $@
$(BUILD)/gen/%.o: $(BUILD)/gen/%.c $(HOST_GEN_HDRS)
	$(CC) $(CSTD) $(OPT) -D_DEFAULT_SOURCE -I$(BUILD)/gen -c $< -o $@
$(BUILD)/gen/%.asan.o: $(BUILD)/gen/%.c $(HOST_GEN_HDRS)
	$(CC) $(CSTD) -O1 -g $(SAN_FLAGS) -D_DEFAULT_SOURCE -I$(BUILD)/gen -c $< -o $@

$(HOST_LIB): $(HOST_OBJS)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^
$(HOST_ASAN_LIB): $(HOST_ASAN_OBJS)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^

# Programs link with g++ when the host library holds C++ (the Box2D adapter).
HOST_LINK = $(if $(HOST_CXX_SRCS),$(CXX),$(CC))
$(BUILD)/bin/%: host_sim/prog/%.c $(HOST_LIB_DEPS) $(CORE_LIB) $(HOST_HDRS)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -c $< -o $(BUILD)/obj/$*.main.o
	$(HOST_LINK) -o $@ $(BUILD)/obj/$*.main.o $(HOST_LIB_DEPS) $(CORE_LIB) $(HOST_LDLIBS)
$(BUILD)/bin/%: firmware/port/linux/prog/%.c $(HOST_LIB_DEPS) $(CORE_LIB) $(HOST_HDRS)
	@mkdir -p $(@D) $(BUILD)/obj
	$(CC) $(HOST_CFLAGS) -Ifirmware -Ifirmware/port/linux -c $< -o $(BUILD)/obj/$*.main.o
	$(HOST_LINK) -o $@ $(BUILD)/obj/$*.main.o $(HOST_LIB_DEPS) $(CORE_LIB) $(HOST_LDLIBS)

ALL_TARGETS += $(HOST_PROGS)

CORE_TESTS := $(patsubst tests/common/%.c,%,$(wildcard tests/common/test_*.c))
$(foreach t,$(CORE_TESTS),$(eval $(call cmocka_test,$(t),tests/common/$(t).c,)))

# --- top-level goals -------------------------------------------------------------------
.PHONY: all deps test test-only bench demo firmware clean help
all: $(ALL_TARGETS)

help:
	@echo "make deps      install missing Debian packages (needs root)"
	@echo "make           build everything for the host into $(BUILD)/"
	@echo "make test      deps + build + every test (plain and ASan+UBSan), summary line last"
	@echo "make firmware  cross-compile the Cortex-M4 image"
	@echo "make bench     print the performance figures (docs/PERFORMANCE.md)"
	@echo "make demo      deps + run the default simulated mission, figures in out/demo/"

deps:
	@scripts/deps.sh

test: deps
	@$(MAKE) --no-print-directory test-only

CORE_CHECK_LIBS := $(CORE_LIB) $(BUILD)/m32/lib/librfs_core.a $(BUILD)/arm/lib/librfs_core.a
TEST_SCRIPTS += "scripts/check_core_symbols.sh nm $(CORE_LIB)"
TEST_SCRIPTS += "scripts/check_core_symbols.sh nm $(BUILD)/m32/lib/librfs_core.a"
TEST_SCRIPTS += "scripts/check_core_symbols.sh arm-none-eabi-nm $(BUILD)/arm/lib/librfs_core.a"

test-only: all $(CORE_CHECK_LIBS) $(TEST_BINS) $(TEST_DEPS)
	@BUILD=$(BUILD) scripts/run_tests.sh $(TEST_BINS) -- $(TEST_SCRIPTS)

bench: all $(BENCH_TARGETS)

clean:
	rm -rf $(BUILD) $(CLEAN_EXTRA)
