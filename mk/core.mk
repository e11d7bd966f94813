# mk/core.mk - the portable core (common/): its library for the host, under ASan+UBSan,
# for -m32 and for the Cortex-M4, the check that it references nothing outside itself,
# its CMocka tests (tests/common/test_<module>.c) and the CAN protocol's DBC check.
# The core: freestanding C11, no float, no libc beyond memcpy/memset/memmove.
CORE_FLAGS := $(CSTD) $(WARN) -ffreestanding -fno-builtin -fno-common $(INC_core)
CORE_OBJS := $(CORE_SRCS:%.c=$(BUILD)/obj/%.o)
CORE_M32_LIB := $(BUILD)/m32/lib/librfs_core.a
CORE_ARM_LIB := $(BUILD)/arm/lib/librfs_core.a

$(BUILD)/obj/common/%.o: common/%.c
	@mkdir -p $(@D)
	$(CC) $(CORE_FLAGS) $(OPT) $(DEPFLAGS) -c $< -o $@
$(BUILD)/asan/obj/common/%.o: common/%.c
	@mkdir -p $(@D)
	$(CC) $(CORE_FLAGS) -O1 -g $(SAN_FLAGS) $(DEPFLAGS) -c $< -o $@
$(BUILD)/m32/obj/common/%.o: common/%.c
	@mkdir -p $(@D)
	$(CC) -m32 $(CORE_FLAGS) -O2 $(DEPFLAGS) -c $< -o $@
$(BUILD)/arm/obj/common/%.o: common/%.c
	@mkdir -p $(@D)
	$(ARM_CC) -mcpu=cortex-m4 -mthumb -mfloat-abi=soft $(CORE_FLAGS) -Os -ffunction-sections -fdata-sections $(DEPFLAGS) -c $< -o $@

$(CORE_LIB): $(CORE_OBJS)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^
$(CORE_ASAN_LIB): $(CORE_SRCS:%.c=$(BUILD)/asan/obj/%.o)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^
$(CORE_M32_LIB): $(CORE_SRCS:%.c=$(BUILD)/m32/obj/%.o)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^
$(CORE_ARM_LIB): $(CORE_SRCS:%.c=$(BUILD)/arm/obj/%.o)
	@mkdir -p $(@D)
	rm -f $@ && arm-none-eabi-ar rcs $@ $^

ALL_TARGETS += $(CORE_LIB)

# The core must also build for -m32 and for the Cortex-M4, and reference nothing outside
# itself but memcpy/memset/memmove.
.PHONY: check-core
check-core: $(CORE_LIB) $(CORE_M32_LIB) $(CORE_ARM_LIB)
	@scripts/check_core_symbols.sh nm $(CORE_LIB)
	@scripts/check_core_symbols.sh nm $(CORE_M32_LIB)
	@scripts/check_core_symbols.sh arm-none-eabi-nm $(CORE_ARM_LIB)
$(eval $(call test_script,core_symbols,scripts/check_core_symbols.sh nm $(CORE_LIB),$(CORE_LIB)))
$(eval $(call test_script,core_symbols_m32,scripts/check_core_symbols.sh nm $(CORE_M32_LIB),$(CORE_M32_LIB)))
$(eval $(call test_script,core_symbols_arm,scripts/check_core_symbols.sh arm-none-eabi-nm $(CORE_ARM_LIB),$(CORE_ARM_LIB)))

# CMocka tests, one per module; test_knn runs scikit-learn through /usr/bin/python3 and
# test_pdr runs tshark, both from the repository root.
CORE_TESTS := $(patsubst tests/common/%.c,%,$(sort $(wildcard tests/common/test_*.c)))
$(foreach t,$(CORE_TESTS),$(eval $(call cmocka_test,$(t),tests/common/$(t).c,core)))

# The CAN protocol: the DBC checked with canmatrix against frames the core encodes.
WIRE_VEC := $(BUILD)/tests/wire/can_vectors
$(WIRE_VEC): tests/wire/can_vectors.c $(CORE_LIB)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) $(INC_core) $(DEPFLAGS) -MF $@.d -MT $@ $< -o $@ $(CORE_LIB)
$(eval $(call test_script,dbc,tests/wire/dbc_test.sh $(BUILD),$(WIRE_VEC)))
