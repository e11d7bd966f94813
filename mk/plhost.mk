# mk/plhost.mk - the path-loss model's estimate and uncertainty in the simulator's outputs
# (issue 10, host side; docs/SIMULATOR.md "Path-loss estimate"): log.tsv columns,
# summary.json, residual.tsv and scripts/plot_run.py's residual.png.

# Pathloss runs (office, L-shaped floor) and a ridge run, read back in python; the plot.
TEST_SCRIPTS += 'tests/host_sim/pathloss_out.sh $(BUILD)/bin/rfseek-sim'

# The estimate in the LCM seeker status: hand-decoded bytes, zero without, bad ones dropped.
$(eval $(call cmocka_test,test_status_est,tests/host_sim/test_status_est.c,))

# rfseekd --model pathloss fills the estimate in its status (two-process run in a netns).
TEST_SCRIPTS += 'tests/host_sim/status_est.sh $(BUILD)'
TEST_DEPS += $(BUILD)/bin/rfseekd $(BUILD)/bin/rfseek-sim-lcm
