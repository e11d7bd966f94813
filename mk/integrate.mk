# mk/integrate.mk - one way to choose the model and the target everywhere (issue 8):
# rfseek-sim --model / `model:` / `target: pdr`, rfseek-feed --model / --target, the
# firmware's model by configuration (rfs_app_cfg_t.model, the CFG record's model name),
# rfseekd --model. docs/MODELS.md, "Choosing a model".

# The firmware's model selection and the CFG record's model name (host, plain and ASan).
$(eval $(call cmocka_test,test_app_models,tests/firmware/test_app_models.c,))

# Every program's options and scenario keys, good and bad values; PDR seeking in the
# simulator; PDR replay of real captures against tshark; the MLP bit-identical on the
# emulated Cortex-M4 and refused models there.
TEST_DEPS += $(BUILD)/bin/rfseek-sim $(BUILD)/bin/rfseek-feed $(FEED)/asan/rfseek-feed \
	$(BUILD)/bin/rfseekd $(BUILD)/bin/rfseek-record $(BUILD)/bin/rfseek-replay firmware
TEST_SCRIPTS += 'tests/host_sim/test_models_cli.sh $(BUILD)'
