/* ref_geom.h - double-precision geometry shared by the map and planner tests. */
#ifndef REF_GEOM_H
#define REF_GEOM_H

#include <math.h>

/* Does the closed segment (x0, y0)-(x1, y1) touch the closed cell square
 * [i r, (i + 1) r] x [j r, (j + 1) r]? Coordinates in Q16 units relative to the map's
 * origin; exact in double (integers below 2^21, products below 2^43). */
static inline int ref_touch(double x0, double y0, double x1, double y1, double r, int i, int j)
{
    double bx0 = i * r, bx1 = (i + 1) * r, by0 = j * r, by1 = (j + 1) * r;
    if (fmax(x0, x1) < bx0 || fmin(x0, x1) > bx1 || fmax(y0, y1) < by0 || fmin(y0, y1) > by1) {
        return 0;
    }
    double cx[4] = {bx0, bx1, bx0, bx1};
    double cy[4] = {by0, by0, by1, by1};
    int pos = 0, neg = 0;
    for (int k = 0; k < 4; k++) {
        double cr = (x1 - x0) * (cy[k] - y0) - (y1 - y0) * (cx[k] - x0);
        pos += cr > 0;
        neg += cr < 0;
    }
    return !(pos == 4 || neg == 4);
}

#endif /* REF_GEOM_H */
