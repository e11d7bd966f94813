# mk/firmware_m4.mk - the Cortex-M4 model bench (issues 8 and 10; docs/PERFORMANCE.md,
# "Models on the Cortex-M4"): build/firmware/bench_models.elf, its host twin and its
# check (which also holds every model's registry fit budget to the 200 ms deadline).
# Included after mk/firmware.mk (sorted names), whose FW_* variables it uses.

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
$(FW)/obj/mw_%_map.o: $(FW)/mw_%_map.c $(FW_ALL_HDRS)
	@mkdir -p $(@D)
	$(ARM_CC) $(FW_CFLAGS) $(MW_MAP_RENAME_$*) -c $< -o $@

FW_BENCH_MODELS_SRCS := firmware/port/stm32f4/startup.c firmware/port/qemu/semihost.c \
	firmware/port/qemu/bench_clock.c firmware/port/qemu/models_work.c \
	firmware/port/qemu/bench_models.c
FW_BENCH_MODELS_OBJS := $(FW_BENCH_MODELS_SRCS:%.c=$(FW)/obj/%.o) $(FW)/obj/mw_box_map.o \
	$(FW)/obj/mw_office_map.o
# The emulator's 1 MB flash / 192 KB RAM; newlib's libm for the workload's doubles.
$(FW)/bench_models.elf: $(FW_BENCH_MODELS_OBJS) $(FW_CORE_LIB) firmware/port/stm32f4/stm32f405.ld
	$(ARM_CC) $(FW_LDFLAGS) -Wl,--defsym=RFS_RAM_BUDGET=192K -Wl,--defsym=RFS_FLASH_BUDGET=1024K \
		-Wl,--defsym=RFS_STACK_SIZE=16K -o $@ $(FW_BENCH_MODELS_OBJS) $(FW_CORE_LIB) -lm

# The host twin: the same run on the host core (the check's reference).
MW_HOST := $(BUILD)/obj/mw_host
MW_HOST_CFLAGS = $(HOST_CFLAGS) -Ifirmware/port/qemu
$(MW_HOST)/models_work.o: firmware/port/qemu/models_work.c $(FW_ALL_HDRS)
	@mkdir -p $(@D)
	$(CC) $(MW_HOST_CFLAGS) -c $< -o $@
$(MW_HOST)/mw_%_map.o: $(FW)/mw_%_map.c $(FW_ALL_HDRS)
	@mkdir -p $(@D)
	$(CC) $(MW_HOST_CFLAGS) $(MW_MAP_RENAME_$*) -c $< -o $@
$(MW_HOST)/bench_models_host.o: tests/firmware/bench_models_host.c $(FW_ALL_HDRS) $(HOST_HDRS)
	@mkdir -p $(@D)
	$(CC) $(MW_HOST_CFLAGS) -c $< -o $@
MW_HOST_OBJS := $(MW_HOST)/bench_models_host.o $(MW_HOST)/models_work.o \
	$(MW_HOST)/mw_box_map.o $(MW_HOST)/mw_office_map.o
$(BUILD)/tests/bench_models_host: $(MW_HOST_OBJS) $(HOST_LIB_DEPS) $(CORE_LIB)
	@mkdir -p $(@D)
	$(HOST_LINK) -o $@ $(MW_HOST_OBJS) $(HOST_LIB_DEPS) $(CORE_LIB) $(HOST_LDLIBS)

TEST_DEPS += $(FW)/bench_models.elf $(BUILD)/tests/bench_models_host
TEST_SCRIPTS += 'tests/firmware/bench_models.sh check $(BUILD)'

# MW_BUDGETS="mlp:600 pathloss:800" adds sliced relearns at candidate budgets beside the
# registry's (how rfs_models_entry_t.mcu_fit_budget was chosen; up to 8 pairs).
MW_BUDGETS ?=
.PHONY: bench-models-m4
bench-models-m4: $(FW)/bench_models.elf
	@tests/firmware/bench_models.sh bench $(BUILD) $(MW_BUDGETS)
BENCH_TARGETS += bench-models-m4
