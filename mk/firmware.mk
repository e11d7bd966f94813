# mk/firmware.mk - the application loop, the STM32F405 image, the emulator image, their
# tests and the instruction-count bench (issue 6; docs/FIRMWARE.md).

# --- host side: rfs_app and rfs_replay go into librfs_host.a (rfseekd links them too) ---
FW_PORTABLE := firmware/rfs_app.c firmware/rfs_replay.c
FW_HDRS := $(wildcard firmware/*.h)
HOST_SRCS += $(FW_PORTABLE)
HOST_CFLAGS += -Ifirmware

$(BUILD)/obj/firmware/%.o: firmware/%.c $(FW_HDRS) $(CORE_HDRS)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -c $< -o $@
$(BUILD)/asan/obj/firmware/%.o: firmware/%.c $(FW_HDRS) $(CORE_HDRS)
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -O1 $(SAN_FLAGS) -c $< -o $@

# --- the Cortex-M4 images ----------------------------------------------------------------
FW := $(BUILD)/firmware
FW_ARCH := -mcpu=cortex-m4 -mthumb -mfloat-abi=soft
FW_OPT ?= -O2
FW_CFLAGS := $(FW_ARCH) $(CSTD) $(WARN) $(FW_OPT) -g -ffreestanding -fno-common \
	-ffunction-sections -fdata-sections -Icommon -Ifirmware -Ifirmware/port/stm32f4 \
	-Ifirmware/port/qemu
FW_LDFLAGS := $(FW_ARCH) -nostartfiles --specs=nano.specs -Wl,--gc-sections \
	-T firmware/port/stm32f4/stm32f405.ld
FW_CORE_LIB := $(FW)/lib/librfs_core.a
FW_CORE_OBJS := $(CORE_SRCS:%.c=$(FW)/obj/%.o)
# The map baked into the hardware image: by default the largest the image holds.
FW_MAP ?= --box 40 20 --res 0.125
FW_STM32_SRCS := firmware/port/stm32f4/startup.c firmware/port/stm32f4/board.c \
	firmware/port/stm32f4/rfs_bxcan.c firmware/port/stm32f4/main.c firmware/rfs_app.c
FW_QEMU_SRCS := firmware/port/stm32f4/startup.c firmware/port/qemu/semihost.c \
	firmware/port/qemu/bench_clock.c firmware/port/qemu/main.c firmware/rfs_app.c firmware/rfs_replay.c
FW_BENCH_SRCS := firmware/port/stm32f4/startup.c firmware/port/qemu/semihost.c \
	firmware/port/qemu/bench_clock.c firmware/port/qemu/bench.c firmware/rfs_app.c
FW_ALL_HDRS := $(CORE_HDRS) $(FW_HDRS) $(wildcard firmware/port/*/*.h)

$(FW)/obj/%.o: %.c $(FW_ALL_HDRS)
	@mkdir -p $(@D)
	$(ARM_CC) $(FW_CFLAGS) -c $< -o $@
$(FW)/obj/fw_map.o: $(FW)/fw_map.c $(FW_ALL_HDRS)
	@mkdir -p $(@D)
	$(ARM_CC) $(FW_CFLAGS) -c $< -o $@
$(FW)/fw_map.c: scripts/map2c.py
	@mkdir -p $(@D)
	$(PYTHON) scripts/map2c.py $(FW_MAP) -o $@
$(FW_CORE_LIB): $(FW_CORE_OBJS)
	@mkdir -p $(@D)
	rm -f $@ && arm-none-eabi-ar rcs $@ $^

$(FW)/firmware.elf: $(FW_STM32_SRCS:%.c=$(FW)/obj/%.o) $(FW)/obj/fw_map.o $(FW_CORE_LIB) firmware/port/stm32f4/stm32f405.ld
	$(ARM_CC) $(FW_LDFLAGS) -Wl,-Map=$(FW)/firmware.map -o $@ $(filter %.o,$^) $(FW_CORE_LIB)
# The emulator image: the hardware stack plus the player's ~1.5 KB, so an overflow of the
# application's path faults here too (the stack sits below .data/.bss).
$(FW)/qemu.elf: $(FW_QEMU_SRCS:%.c=$(FW)/obj/%.o) $(FW_CORE_LIB) firmware/port/stm32f4/stm32f405.ld
	$(ARM_CC) $(FW_LDFLAGS) -Wl,--defsym=RFS_RAM_BUDGET=192K -Wl,--defsym=RFS_FLASH_BUDGET=1024K -Wl,--defsym=RFS_STACK_SIZE=4K -o $@ $(filter %.o,$^) $(FW_CORE_LIB)
$(FW)/bench.elf: $(FW_BENCH_SRCS:%.c=$(FW)/obj/%.o) $(FW_CORE_LIB) firmware/port/stm32f4/stm32f405.ld
	$(ARM_CC) $(FW_LDFLAGS) -Wl,--defsym=RFS_RAM_BUDGET=192K -Wl,--defsym=RFS_FLASH_BUDGET=1024K -Wl,--defsym=RFS_STACK_SIZE=16K -o $@ $(filter %.o,$^) $(FW_CORE_LIB)
$(FW)/%.bin: $(FW)/%.elf
	arm-none-eabi-objcopy -O binary $< $@

.PHONY: firmware
firmware: $(FW)/firmware.elf $(FW)/firmware.bin $(FW)/qemu.elf
	@arm-none-eabi-size $(FW)/firmware.elf $(FW)/qemu.elf
	@scripts/fw_budget.sh $(FW)/firmware.elf

# --- tests -------------------------------------------------------------------------------
# The driver under test is compiled on its own (the cmocka_test macro takes one C file
# when the link driver is g++), plain and under ASan+UBSan.
$(BUILD)/tests/test_bxcan: tests/firmware/test_bxcan.c $(BUILD)/obj/firmware/port/stm32f4/rfs_bxcan.o $(CORE_LIB) tests/rfs_test.h
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -Itests tests/firmware/test_bxcan.c $(BUILD)/obj/firmware/port/stm32f4/rfs_bxcan.o -o $@ $(CORE_LIB) -lcmocka
$(BUILD)/asan/tests/test_bxcan: tests/firmware/test_bxcan.c $(BUILD)/asan/obj/firmware/port/stm32f4/rfs_bxcan.o $(CORE_ASAN_LIB) tests/rfs_test.h
	@mkdir -p $(@D)
	$(CC) $(HOST_CFLAGS) -O1 $(SAN_FLAGS) -Itests tests/firmware/test_bxcan.c $(BUILD)/asan/obj/firmware/port/stm32f4/rfs_bxcan.o -o $@ $(CORE_ASAN_LIB) -lcmocka
TEST_BINS += $(BUILD)/tests/test_bxcan $(BUILD)/asan/tests/test_bxcan
$(eval $(call cmocka_test,test_replay,tests/firmware/test_replay.c,))
$(eval $(call cmocka_test,test_app,tests/firmware/test_app.c,))
TEST_DEPS += firmware $(BUILD)/bin/rfseek-replay $(BUILD)/bin/rfseek-record
TEST_SCRIPTS += 'tests/firmware/bit_identical.sh $(BUILD)'
TEST_SCRIPTS += 'tests/firmware/safety.sh $(BUILD)'
TEST_SCRIPTS += 'tests/firmware/budget.sh $(BUILD)'

# libFuzzer target over the stream parser and the player (clang only, like feed's).
FW_FUZZ_CC ?= clang
$(FW)/fuzz_replay: tests/fuzz/fuzz_replay.c $(FW_PORTABLE) $(CORE_SRCS) $(FW_HDRS) $(CORE_HDRS)
	@mkdir -p $(@D)
	$(FW_FUZZ_CC) -std=c11 -g -O1 -Icommon -Ifirmware -fsanitize=fuzzer,address,undefined \
		-fno-sanitize-recover=all tests/fuzz/fuzz_replay.c $(FW_PORTABLE) $(CORE_SRCS) -o $@
TEST_DEPS += $(FW)/fuzz_replay
TEST_SCRIPTS += 'tests/fuzz/run_one.sh $(FW)/fuzz_replay $(FW)/fuzz-corpus tests/fuzz/corpus/replay 2000'

# --- bench -------------------------------------------------------------------------------
.PHONY: bench-firmware
bench-firmware: $(FW)/bench.elf firmware
	@tests/firmware/bench.sh $(BUILD)
BENCH_TARGETS += bench-firmware
