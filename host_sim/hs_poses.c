/* hs_poses.c - the pose CSV of rfseek-feed --pose (hs_poses.h). */
#include "hs_poses.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

int hs_poses_read(FILE *fp, const char *name, hs_pose_rec_t **out, size_t *n_out, char *err, size_t errlen)
{
    hs_pose_rec_t *v = NULL;
    size_t n = 0, cap = 0;
    char line[512];
    unsigned long ln = 0;
    int rc = 0;
    while (fgets(line, sizeof(line), fp) != NULL) {
        ln++;
        const size_t len = strlen(line);
        if (len == sizeof(line) - 1 && line[len - 1] != '\n') {
            snprintf(err, errlen, "%s:%lu: line longer than %zu bytes", name, ln, sizeof(line) - 2);
            rc = -1;
            break;
        }
        line[strcspn(line, "\r\n")] = '\0';
        if (ln == 1) {
            if (strcmp(line, "t_us,x_m,y_m,theta_rad") != 0) {
                snprintf(err, errlen, "%s:1: header must be 't_us,x_m,y_m,theta_rad'", name);
                rc = -1;
                break;
            }
            continue;
        }
        if (line[0] == '\0') { continue; }
        hs_pose_rec_t p;
        char *e = NULL;
        errno = 0;
        p.t_us = strtoll(line, &e, 10);
        if (e == line || *e != ',' || errno != 0) {
            snprintf(err, errlen, "%s:%lu: t_us: not an integer number of microseconds", name, ln);
            rc = -1;
            break;
        }
        if (p.t_us < 0 || p.t_us > HS_POSES_T_MAX) {
            snprintf(err, errlen, "%s:%lu: t_us: %lld out of range (0 .. %lld microseconds since the epoch)",
                     name, ln, (long long)p.t_us, (long long)HS_POSES_T_MAX);
            rc = -1;
            break;
        }
        // cppcheck-suppress uninitvar ; only addresses are taken; each field is written below
        double *fields[3] = {&p.x, &p.y, &p.theta};
        static const char *names[3] = {"x_m", "y_m", "theta_rad"};
        for (int k = 0; k < 3 && rc == 0; k++) {
            const char *b = e + 1;
            *fields[k] = strtod(b, &e);
            if (e == b || (k < 2 ? *e != ',' : *e != '\0') || !isfinite(*fields[k])) {
                snprintf(err, errlen, "%s:%lu: %s: not a finite number%s", name, ln, names[k],
                         k < 2 ? " followed by ','" : " at the end of the line");
                rc = -1;
            } else if (k < 2 && fabs(*fields[k]) > HS_POSES_XY_MAX) {
                snprintf(err, errlen, "%s:%lu: %s: %g out of range (-%g .. %g m)", name, ln, names[k],
                         *fields[k], HS_POSES_XY_MAX, HS_POSES_XY_MAX);
                rc = -1;
            }
        }
        if (rc != 0) { break; }
        if (n > 0 && p.t_us <= v[n - 1].t_us) {
            snprintf(err, errlen, "%s:%lu: t_us: %lld is not after the previous pose (%lld)", name, ln,
                     (long long)p.t_us, (long long)v[n - 1].t_us);
            rc = -1;
            break;
        }
        if (n == cap) {
            cap = cap ? cap * 2 : 1024;
            hs_pose_rec_t *nv = realloc(v, cap * sizeof(*nv));
            if (nv == NULL) { snprintf(err, errlen, "%s: out of memory", name); rc = -1; break; }
            v = nv;
        }
        v[n++] = p;
    }
    if (rc == 0 && ferror(fp)) { snprintf(err, errlen, "%s: read error", name); rc = -1; }
    if (rc == 0 && n < 2) { snprintf(err, errlen, "%s: fewer than 2 poses", name); rc = -1; }
    if (rc != 0) { free(v); return -1; }
    *out = v;
    *n_out = n;
    return 0;
}

int hs_poses_load(const char *path, hs_pose_rec_t **out, size_t *n, char *err, size_t errlen)
{
    FILE *fp = fopen(path, "r");
    if (fp == NULL) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    const int rc = hs_poses_read(fp, path, out, n, err, errlen);
    fclose(fp);
    return rc;
}

double hs_poses_wrap(double a)
{
    /* Beyond 32 turns, IEEE remainder (exact) first; below, the subtraction loop alone,
     * which earlier replays used and whose roundings they keep. */
    if (fabs(a) > 64.0 * M_PI) { a = remainder(a, 2.0 * M_PI); }
    while (a > M_PI) { a -= 2.0 * M_PI; }
    while (a <= -M_PI) { a += 2.0 * M_PI; }
    return a;
}
