# mk/firmware.mk - the application loop (firmware/rfs_app.c, rfs_replay.c) as a host
# library, the STM32F405 image, the emulator images, the Cortex-M4 model workload and its
# host twin, and their tests (docs/FIRMWARE.md).

# --- host side: librfs_fw.a (rfseekd, rfseek-replay, rfseek-record and the tests link it) --
FW_PORTABLE := firmware/rfs_app.c firmware/rfs_replay.c
FW_CFLAGS_HOST := $(HOST_CFLAGS) $(INC_fw)

$(BUILD)/obj/firmware/%.o: firmware/%.c
	@mkdir -p $(@D)
	$(CC) $(FW_CFLAGS_HOST) $(DEPFLAGS) -c $< -o $@
$(BUILD)/asan/obj/firmware/%.o: firmware/%.c
	@mkdir -p $(@D)
	$(CC) $(FW_CFLAGS_HOST) -O1 $(SAN_FLAGS) $(DEPFLAGS) -c $< -o $@
$(FW_LIB): $(FW_PORTABLE:%.c=$(BUILD)/obj/%.o)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^
$(FW_ASAN_LIB): $(FW_PORTABLE:%.c=$(BUILD)/asan/obj/%.o)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^
ALL_TARGETS += $(FW_LIB)

# --- the Cortex-M4 images ----------------------------------------------------------------
FW_ARCH := -mcpu=cortex-m4 -mthumb -mfloat-abi=soft
FW_OPT ?= -O2
FW_CFLAGS := $(FW_ARCH) $(CSTD) $(WARN) $(FW_OPT) -g -ffreestanding -fno-common -fstack-usage \
	-ffunction-sections -fdata-sections $(INC_fw) -Ifirmware/port/stm32f4 -Ifirmware/port/qemu
FW_LDFLAGS := $(FW_ARCH) -nostartfiles --specs=nano.specs -Wl,--gc-sections \
	-T firmware/port/stm32f4/stm32f405.ld
# The emulator's 1 MB flash and 192 KB RAM: the benchmarks use it all; the replay image
# splits it as the hardware's SRAM and CCM (128 KB + 64 KB at 0x20020000: qemu has no CCM).
FW_EMU_LDFLAGS := $(FW_LDFLAGS) -Wl,--defsym=RFS_FLASH_BUDGET=1024K
FW_BENCH_LDFLAGS := $(FW_EMU_LDFLAGS) -Wl,--defsym=RFS_RAM_LENGTH=192K -Wl,--defsym=RFS_RAM_BUDGET=192K
FW_QEMU_LDFLAGS := $(FW_EMU_LDFLAGS) -Wl,--defsym=RFS_CCM_ORIGIN=0x20020000
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
FW_IMAGES := $(FW)/firmware.elf $(FW)/firmware.bin $(FW)/qemu.elf

# The flags the objects were built with: a change rebuilds them all (an object built before
# -fstack-usage has no .su file for tests/firmware/stack.sh).
FW_FLAGS_STAMP := $(FW)/cflags.txt
.PHONY: FORCE
FORCE:
$(FW_FLAGS_STAMP): FORCE
	@mkdir -p $(@D)
	@echo '$(ARM_CC) $(FW_CFLAGS)' | cmp -s - $@ || echo '$(ARM_CC) $(FW_CFLAGS)' > $@
$(FW)/obj/%.o: %.c $(FW_FLAGS_STAMP)
	@mkdir -p $(@D)
	$(ARM_CC) $(FW_CFLAGS) $(DEPFLAGS) -c $< -o $@
$(FW)/obj/fw_map.o: $(FW)/fw_map.c $(FW_FLAGS_STAMP)
	@mkdir -p $(@D)
	$(ARM_CC) $(FW_CFLAGS) $(DEPFLAGS) -c $< -o $@
$(FW)/fw_map.c: scripts/map2c.py
	@mkdir -p $(@D)
	$(PYTHON) scripts/map2c.py $(FW_MAP) -o $@
$(FW_CORE_LIB): $(FW_CORE_OBJS)
	@mkdir -p $(@D)
	rm -f $@ && arm-none-eabi-ar rcs $@ $^

$(FW)/firmware.elf: $(FW_STM32_SRCS:%.c=$(FW)/obj/%.o) $(FW)/obj/fw_map.o $(FW_CORE_LIB) firmware/port/stm32f4/stm32f405.ld
	$(ARM_CC) $(FW_LDFLAGS) -Wl,-Map=$(FW)/firmware.map -o $@ $(filter %.o,$^) $(FW_CORE_LIB)
# The emulator image: a 4 KB stack below .data/.bss, so an overflow faults here too (the
# replay player's frames are not the hardware loop's: its bound is tests/firmware/stack.sh).
$(FW)/qemu.elf: $(FW_QEMU_SRCS:%.c=$(FW)/obj/%.o) $(FW_CORE_LIB) firmware/port/stm32f4/stm32f405.ld
	$(ARM_CC) $(FW_QEMU_LDFLAGS) -Wl,--defsym=RFS_STACK_SIZE=4K -o $@ $(filter %.o,$^) $(FW_CORE_LIB)
$(FW)/bench.elf: $(FW_BENCH_SRCS:%.c=$(FW)/obj/%.o) $(FW_CORE_LIB) firmware/port/stm32f4/stm32f405.ld
	$(ARM_CC) $(FW_BENCH_LDFLAGS) -Wl,--defsym=RFS_STACK_SIZE=16K -o $@ $(filter %.o,$^) $(FW_CORE_LIB)
$(FW)/%.bin: $(FW)/%.elf
	arm-none-eabi-objcopy -O binary $< $@

.PHONY: firmware
firmware: $(FW_IMAGES)
	@arm-none-eabi-size $(FW)/firmware.elf $(FW)/qemu.elf
	@scripts/fw_budget.sh $(FW)/firmware.elf
	@scripts/fw_budget.sh $(FW)/qemu.elf

# --- the model workload on the Cortex-M4 (docs/PERFORMANCE.md, "Models on the Cortex-M4")
# The two maps of the workloads, baked as const grids; map2c.py names the object
# rfs_fw_map, renamed here so both fit in one image.
$(FW)/mw_box_map.c: scripts/map2c.py
	@mkdir -p $(@D)
	$(PYTHON) scripts/map2c.py --box 40 20 --res 0.125 -o $@
$(FW)/mw_office_map.c: scripts/map2c.py scenarios/maps/office.yaml scenarios/maps/office.pgm
	@mkdir -p $(@D)
	$(PYTHON) scripts/map2c.py scenarios/maps/office.yaml --res 0.1 -o $@
MW_MAP_RENAME_box := -Drfs_fw_map=rfs_mw_box_map
MW_MAP_RENAME_office := -Drfs_fw_map=rfs_mw_office_map
$(FW)/obj/mw_%_map.o: $(FW)/mw_%_map.c
	@mkdir -p $(@D)
	$(ARM_CC) $(FW_CFLAGS) $(MW_MAP_RENAME_$*) $(DEPFLAGS) -c $< -o $@

FW_BENCH_MODELS_SRCS := firmware/port/stm32f4/startup.c firmware/port/qemu/semihost.c \
	firmware/port/qemu/bench_clock.c firmware/port/qemu/models_work.c \
	firmware/port/qemu/bench_models.c
FW_BENCH_MODELS_OBJS := $(FW_BENCH_MODELS_SRCS:%.c=$(FW)/obj/%.o) $(FW)/obj/mw_box_map.o \
	$(FW)/obj/mw_office_map.o
# newlib's libm for the workload's doubles.
$(FW)/bench_models.elf: $(FW_BENCH_MODELS_OBJS) $(FW_CORE_LIB) firmware/port/stm32f4/stm32f405.ld
	$(ARM_CC) $(FW_BENCH_LDFLAGS) -Wl,--defsym=RFS_STACK_SIZE=16K -o $@ $(FW_BENCH_MODELS_OBJS) $(FW_CORE_LIB) -lm

# The host twin: the same run on the host core (the check's reference); it reads the
# office map through the Linux port's loader.
MW_HOST := $(BUILD)/obj/mw_host
MW_HOST_CFLAGS := $(HOST_CFLAGS) $(INC_linux) -Ifirmware/port/qemu
$(MW_HOST)/models_work.o: firmware/port/qemu/models_work.c
	@mkdir -p $(@D)
	$(CC) $(MW_HOST_CFLAGS) $(DEPFLAGS) -c $< -o $@
$(MW_HOST)/mw_%_map.o: $(FW)/mw_%_map.c
	@mkdir -p $(@D)
	$(CC) $(MW_HOST_CFLAGS) $(MW_MAP_RENAME_$*) $(DEPFLAGS) -c $< -o $@
$(MW_HOST)/bench_models_host.o: tests/firmware/bench_models_host.c
	@mkdir -p $(@D)
	$(CC) $(MW_HOST_CFLAGS) $(DEPFLAGS) -c $< -o $@
MW_HOST_OBJS := $(MW_HOST)/bench_models_host.o $(MW_HOST)/models_work.o \
	$(MW_HOST)/mw_box_map.o $(MW_HOST)/mw_office_map.o
$(BUILD)/tests/bench_models_host: $(MW_HOST_OBJS) $(LIBS_linux)
	@mkdir -p $(@D)
	$(LD_linux) -o $@ $(MW_HOST_OBJS) $(LIBS_linux) $(LDLIBS_linux)

# --- tests -------------------------------------------------------------------------------
# The bxCAN driver compiled for the host on its own, plain and under ASan+UBSan.
$(BUILD)/tests/test_bxcan: tests/firmware/test_bxcan.c $(BUILD)/obj/firmware/port/stm32f4/rfs_bxcan.o $(CORE_LIB)
	@mkdir -p $(@D)
	$(CC) $(FW_CFLAGS_HOST) $(DEPFLAGS) -MF $@.d -MT $@ -Itests tests/firmware/test_bxcan.c $(BUILD)/obj/firmware/port/stm32f4/rfs_bxcan.o -o $@ $(CORE_LIB) -lcmocka
$(BUILD)/asan/tests/test_bxcan: tests/firmware/test_bxcan.c $(BUILD)/asan/obj/firmware/port/stm32f4/rfs_bxcan.o $(CORE_ASAN_LIB)
	@mkdir -p $(@D)
	$(CC) $(FW_CFLAGS_HOST) -O1 $(SAN_FLAGS) $(DEPFLAGS) -MF $@.d -MT $@ -Itests tests/firmware/test_bxcan.c $(BUILD)/asan/obj/firmware/port/stm32f4/rfs_bxcan.o -o $@ $(CORE_ASAN_LIB) -lcmocka
TEST_BIN_NAMES += test_bxcan
$(eval $(call cmocka_test,test_replay,tests/firmware/test_replay.c,fw))
$(eval $(call cmocka_test,test_app,tests/firmware/test_app.c,fw))
$(eval $(call cmocka_test,test_board,tests/firmware/test_board.c,fw))
# The model chosen by configuration and the CFG record's model name (docs/MODELS.md,
# "Choosing a model").
$(eval $(call cmocka_test,test_app_models,tests/firmware/test_app_models.c,fw))

# Host and emulated Cortex-M4 outputs bit-identical; the application's safety rules; the
# flash and RAM budget.
FW_TEST_PROGS := $(FW_IMAGES) $(BUILD)/bin/rfseek-replay $(BUILD)/bin/rfseek-record
$(eval $(call test_script,bit_identical,tests/firmware/bit_identical.sh $(BUILD),$(FW_TEST_PROGS)))
$(eval $(call test_script,safety,tests/firmware/safety.sh $(BUILD),$(FW_TEST_PROGS)))
$(eval $(call test_script,budget,tests/firmware/budget.sh $(BUILD),$(FW_IMAGES)))
$(eval $(call test_script,stack,tests/firmware/stack.sh $(BUILD),$(FW_IMAGES) scripts/fw_stack.py))
$(eval $(call test_script,boot_order,tests/firmware/boot_order.sh $(BUILD),$(FW_IMAGES)))
# The model workload on the emulator against its host twin, and every model's registry fit
# budget against the 200 ms deadline.
$(eval $(call test_script,bench_models,tests/firmware/bench_models.sh check $(BUILD),$(FW)/bench_models.elf $(BUILD)/tests/bench_models_host))
