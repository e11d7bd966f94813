/* fuzz_map - libFuzzer target for the ROS map_server loader (firmware/port/linux/lx_map.h).
 *
 * Input: the YAML text, then the 5 bytes "#PGM\n", then the image file's bytes (no
 * separator: everything is YAML and the image is empty). They are written to m.yaml and
 * m.pgm in a private tmpfs directory and loaded with lx_map_load(). Every '/' in the YAML
 * becomes '_' so `image:` can only name files inside that directory (never /dev/zero or
 * a file of the machine); the seeds say `image: m.pgm`.
 *
 * Beyond ASan/UBSan it checks the header's promises: failure gives one non-empty error
 * line and leaves nothing allocated (LeakSanitizer); success gives 1..2^26 cells, each
 * LX_CELL_*, a positive resolution, thresholds in [0, 1] with free < occupied, negate
 * 0/1, and counts that add up; conversion to the core either fails with one line or
 * yields a grid covering the image (up to the documented sliver).
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_tmp.h"
#include "lx_map.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char sep[] = "#PGM\n";
    size_t ylen = size, ioff = size;
    for (size_t i = 0; i + 5u <= size; i++) {
        if (memcmp(data + i, sep, 5) == 0) {
            ylen = i;
            ioff = i + 5u;
            break;
        }
    }
    char *y = malloc(ylen + 1u);
    if (y == NULL) { return 0; }
    memcpy(y, data, ylen);
    for (size_t i = 0; i < ylen; i++) {
        if (y[i] == '/') { y[i] = '_'; }
    }
    const char *ypath = fuzz_tmp_write(0, "m.yaml", y, ylen);
    free(y);
    (void)fuzz_tmp_write(1, "m.pgm", data + ioff, size - ioff);

    lx_map_t m;
    memset(&m, 0, sizeof m);
    char err[512] = "";
    if (lx_map_load(ypath, &m, err, sizeof err) != 0) {
        fuzz_check_err_line(err);
        if (m.cell != NULL) { abort(); }
        return 0;
    }
    const uint64_t n = (uint64_t)m.w * m.h;
    if (n == 0 || n > (1ull << 26) || m.cell == NULL || !(m.res > 0.0) || !isfinite(m.res) ||
        !isfinite(m.origin_x) || !isfinite(m.origin_y) || !(m.free_th < m.occ_th) || m.free_th < 0.0 ||
        m.occ_th > 1.0 || (m.negate != 0 && m.negate != 1)) {
        abort();
    }
    for (uint64_t i = 0; i < n; i++) {
        if (m.cell[i] > LX_CELL_UNKNOWN) { abort(); }
    }
    uint32_t nf = 0, no = 0, nu = 0;
    lx_map_count(&m, &nf, &no, &nu);
    if ((uint64_t)nf + no + nu != n) { abort(); }

    /* Conversion at the simulator's default core resolution and at the map's own. */
    const double res[2] = {0.1, m.res};
    for (int k = 0; k < 2; k++) {
        lx_core_map_t c;
        memset(&c, 0, sizeof c);
        char e2[512] = "";
        if (lx_map_to_core(&m, res[k], NULL, &c, e2, sizeof e2) != 0) {
            fuzz_check_err_line(e2);
        } else {
            /* The grid may leave out a sliver of up to 0.1 fine cell (LX_MAP_SLIVER, against
             * resolution rounding) plus the Q16.16 rounding of resolution and origin. */
            const double cr = (double)c.map.res / 65536.0;
            const double tol = 0.1 * m.res + 1e-4 + 1e-6 * (m.w + m.h) * m.res;
            if (c.free_bits == NULL || c.wall_bits == NULL || c.legal_bits == NULL ||
                (double)c.map.w * cr < (double)m.w * m.res - tol || (double)c.map.h * cr < (double)m.h * m.res - tol) {
                abort();
            }
        }
        lx_core_map_free(&c);
    }
    lx_map_free(&m);
    if (m.cell != NULL) { abort(); }
    return 0;
}
