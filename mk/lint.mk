# mk/lint.mk - static analysis (docs/RELIABILITY.md): cppcheck and clang-tidy over common/,
# firmware/ and host_sim/ with the documented check set, and the layer check (includes go
# host_sim -> firmware/port/linux -> firmware -> common, never back; each outside library
# from its one adapter); must end clean.
#   make lint [LINT_JOBS=2]
# clang-tidy needs the generated LCM headers.
LINT_JOBS ?= 2
.PHONY: lint
lint: $(LCM_GEN_HDRS)
	@scripts/check_layers.sh
	@LINT_JOBS=$(LINT_JOBS) scripts/lint/run_lint.sh $(BUILD) cppcheck clang-tidy

$(eval $(call test_script,layers,scripts/check_layers.sh,))
# The docs' section links and scenario keys against the code (scripts/check_docs.py).
$(eval $(call test_script,docs,$(PYTHON) scripts/check_docs.py,))
$(eval $(call test_script,docs_checker,tests/docs/check_docs_test.sh $(PYTHON),))
