/* fuzz_scenario - libFuzzer target for the simulator's scenario loader
 * (host_sim/hs_scenario.h, issue 9). The input is the scenario file, written to a private
 * tmpfs directory and loaded with hs_scenario_load() (which resolves but does not open
 * the map, so nothing outside that directory is read).
 *
 * Beyond ASan/UBSan it checks the header's promises: failure gives one non-empty error
 * line; success gives 1..HS_SCN_MAX_SOURCES sources, finite positions and rates,
 * NUL-terminated names, and a map path.
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_tmp.h"
#include "hs_scenario.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static hs_scenario_t g_sc; /* 2 KiB of paths: keep it off the fuzzer's stack */

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_tmp_write(0, "s.yaml", data, size);
    char err[512] = "";
    if (hs_scenario_load(path, &g_sc, err, sizeof err) != 0) {
        fuzz_check_err_line(err);
        return 0;
    }
    const hs_scenario_t *s = &g_sc;
    if (s->nsources < 1u || s->nsources > HS_SCN_MAX_SOURCES || s->map_path[0] == '\0' ||
        memchr(s->map_path, '\0', sizeof s->map_path) == NULL || memchr(s->model, '\0', sizeof s->model) == NULL ||
        memchr(s->target, '\0', sizeof s->target) == NULL || memchr(s->strategy, '\0', sizeof s->strategy) == NULL ||
        !isfinite(s->start_x) || !isfinite(s->start_y) || !isfinite(s->start_theta) ||
        !(s->physics_hz > 0.0) || !(s->core_res_m > 0.0) || !isfinite(s->clearance_m)) {
        abort();
    }
    for (unsigned i = 0; i < s->nsources; i++) {
        const hs_scn_source_t *src = &s->src[i];
        if (memchr(src->name, '\0', sizeof src->name) == NULL || !isfinite(src->x) || !isfinite(src->y) ||
            !(src->rate_hz > 0.0) || !isfinite(src->tx_dbm)) {
            abort();
        }
    }
    return 0;
}
