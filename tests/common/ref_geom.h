/* ref_geom.h - double-precision geometry shared by the map and planner tests. */
#ifndef REF_GEOM_H
#define REF_GEOM_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

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

/* Gap in cells along one axis between the closed squares of cells a and b (0 when they
 * touch or are the same): rfs_map.h's whole-cell legality compares the Euclidean gap
 * between two squares with the clearance. */
static inline double ref_cell_gap(int a, int b)
{
    int d = abs(a - b);
    return d > 1 ? d - 1 : 0;
}

/* Is the lattice step from (ui, uj) to the neighbour (vi, vj) usable: the neighbour legal
 * and the segment between them legal (each test's own double-precision reference)? */
typedef int (*ref_step_fn)(void *ctx, int ui, int uj, int vi, int vj);

/* Breadth-first flood over the lw x lh lattice (8 neighbours) from (si, sj) through the
 * steps `ok` allows, into one bit per point (idx = j * lw + i: bit idx & 7 of byte
 * idx >> 3, the layout rfs_plan_set_component and the seeker's reach bits use). */
static inline void ref_flood(int lw, int lh, int si, int sj, ref_step_fn ok, void *ctx,
                             uint8_t *bits)
{
    int n = lw * lh, head = 0, tail = 0;
    int *q = malloc(sizeof(int) * (size_t)n);
    memset(bits, 0, (size_t)(n + 7) / 8);
    q[tail++] = sj * lw + si;
    bits[(sj * lw + si) >> 3] |= (uint8_t)(1u << ((sj * lw + si) & 7));
    while (head < tail) {
        int u = q[head++], ui = u % lw, uj = u / lw;
        for (int dj = -1; dj <= 1; dj++) {
            for (int di = -1; di <= 1; di++) {
                int vi = ui + di, vj = uj + dj, v = vj * lw + vi;
                if ((di == 0 && dj == 0) || vi < 0 || vj < 0 || vi >= lw || vj >= lh ||
                    ((bits[v >> 3] >> (v & 7)) & 1) || !ok(ctx, ui, uj, vi, vj)) {
                    continue;
                }
                bits[v >> 3] |= (uint8_t)(1u << (v & 7));
                q[tail++] = v;
            }
        }
    }
    free(q);
}

#endif /* REF_GEOM_H */
