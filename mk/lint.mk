# mk/lint.mk - static analysis (issue 9, docs/RELIABILITY.md): cppcheck and clang-tidy over
# common/, firmware/ and host_sim/ with the documented check set; must end clean.
#   make lint [LINT_JOBS=2]
# Needs the generated LCM headers ($(BUILD)/gen; the list is from mk/fuzz.mk, read first).
LINT_JOBS ?= 2
.PHONY: lint
lint: $(FUZZ_LCM_GEN_HDRS)
	@LINT_JOBS=$(LINT_JOBS) scripts/lint/run_lint.sh $(BUILD) cppcheck clang-tidy
