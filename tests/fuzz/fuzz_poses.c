/* fuzz_poses - libFuzzer target for the pose CSV of rfseek-feed --pose (host_sim/hs_poses.h).
 *
 * Input: the CSV text, read from memory (fmemopen) with hs_poses_read(). Beyond ASan/UBSan
 * it checks the header's promises: failure gives one non-empty error line and leaves
 * nothing allocated (LeakSanitizer); success gives at least 2 poses, times strictly
 * increasing in 0 .. HS_POSES_T_MAX, finite coordinates within +-HS_POSES_XY_MAX, and
 * every heading wraps into (-pi, pi] (in bounded time: libFuzzer's -timeout catches a loop).
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hs_poses.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0) { return 0; } /* fmemopen refuses an empty buffer */
    FILE *f = fmemopen((void *)data, size, "r");
    if (f == NULL) { abort(); }
    hs_pose_rec_t *v = NULL;
    size_t n = 0;
    char err[512] = "";
    const int rc = hs_poses_read(f, "poses.csv", &v, &n, err, sizeof err);
    fclose(f);
    if (rc != 0) {
        if (err[0] == '\0' || strchr(err, '\n') != NULL) { abort(); } /* one non-empty line */
        return 0;
    }
    if (n < 2 || v == NULL) { abort(); }
    for (size_t i = 0; i < n; i++) {
        const hs_pose_rec_t *p = &v[i];
        const double w = hs_poses_wrap(p->theta);
        if (p->t_us < 0 || p->t_us > HS_POSES_T_MAX || (i > 0 && p->t_us <= v[i - 1].t_us) ||
            !(fabs(p->x) <= HS_POSES_XY_MAX) || !(fabs(p->y) <= HS_POSES_XY_MAX) || !isfinite(p->theta) ||
            !(w > -M_PI && w <= M_PI)) {
            abort();
        }
    }
    free(v);
    return 0;
}
