/* hs_poses.h - the recorded poses of a real run, as rfseek-feed --pose reads them.
 *
 * A CSV with the header "t_us,x_m,y_m,theta_rad", then one pose per line: the capture
 * clock in microseconds since the Unix epoch (strictly increasing), the position in the
 * map frame in metres and the heading in radians (docs/FEEDER.md). Every value is range
 * checked, so the replay's time differences, its Q16.16 conversions and its angle wrap
 * are defined for anything the file holds.
 */
#ifndef HS_POSES_H
#define HS_POSES_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/// Latest t_us accepted: 2^53 microseconds (year 2255), exact in a double.
#define HS_POSES_T_MAX (INT64_C(1) << 53)
/// Largest |x_m| and |y_m| accepted, metres: the range of Q16.16.
#define HS_POSES_XY_MAX 32767.0

/// One recorded pose.
typedef struct hs_pose_rec {
    int64_t t_us;       ///< capture clock, microseconds since the epoch (0 .. HS_POSES_T_MAX)
    double x, y, theta; ///< map frame: metres, metres, radians (any finite value)
} hs_pose_rec_t;

/// Read the CSV from the open stream `fp` (`name` for messages): 0 with *out (malloc'd,
/// the caller frees it) holding *n >= 2 poses; or -1 with one line "name:line: field:
/// reason" in err and nothing allocated.
int hs_poses_read(FILE *fp, const char *name, hs_pose_rec_t **out, size_t *n, char *err, size_t errlen);

/// hs_poses_read() on the file at `path` ("path: cannot open: ..." when it cannot be).
int hs_poses_load(const char *path, hs_pose_rec_t **out, size_t *n, char *err, size_t errlen);

/// The angle `a` (finite, radians) wrapped to (-pi, pi], in bounded time whatever its size.
double hs_poses_wrap(double a);

#endif /* HS_POSES_H */
