/* fuzz_scenario - libFuzzer target for the simulator's scenario loader
 * (host_sim/hs_scenario.h). The input is the scenario file, written to a private
 * tmpfs directory and loaded with hs_scenario_load() (which resolves but does not open
 * the map, so nothing outside that directory is read).
 *
 * Beyond ASan/UBSan it checks the header's promises: failure gives one non-empty error
 * line; success gives 1..HS_SCN_MAX_SOURCES sources, finite positions and rates,
 * NUL-terminated names, and a map path. The raw input also goes through the MAC parser.
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

/* The MAC parser on the raw input: accepted only for exactly "hh:hh:hh:hh:hh:hh", with the
 * bytes an independent hex decode gives (found: %2x once let "-1:..." through). */
static void check_mac(const uint8_t *data, size_t size)
{
    char s[32];
    const size_t n = size < sizeof s - 1u ? size : sizeof s - 1u;
    memcpy(s, data, n);
    s[n] = '\0';
    uint8_t mac[6];
    if (hs_scenario_parse_mac(s, mac) != 0) { return; }
    if (strlen(s) != 17u) { abort(); }
    for (int i = 0; i < 17; i++) {
        const char c = s[i];
        const int d = (c >= '0' && c <= '9') ? c - '0' : (c >= 'a' && c <= 'f') ? c - 'a' + 10
                    : (c >= 'A' && c <= 'F') ? c - 'A' + 10 : -1;
        if (i % 3 == 2 ? c != ':' : d < 0) { abort(); }
        if (i % 3 == 1) {
            const char h = s[i - 1];
            const int dh = (h >= '0' && h <= '9') ? h - '0' : (h | 0x20) - 'a' + 10;
            if (mac[i / 3] != (uint8_t)(dh * 16 + d)) { abort(); }
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    check_mac(data, size);
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
