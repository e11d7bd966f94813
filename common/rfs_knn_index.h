/* rfs_knn_index.h - a finer index a host attaches to a nearest-neighbour model
 * (rfs_knn.h) so that its predictions read fewer samples; the firmware runs without it.
 *
 * RFS_KNN_FINE^2 sub-cells per grid cell, the samples of each sorted by position (equal
 * positions in their order in rfs_knn_t.pts), rebuilt when a fit completes (no work unit
 * changes). predict() then reads only the sub-cells that can hold a neighbour, one
 * distance per position: k-neighbours keeps the k best by (distance, the place at which
 * the plain ring scan meets the sample), so ties at the k-th distance go as they do
 * without the index; radius sums whole sub-cells and positions from prefix sums. The
 * predictions are the plain ones bit for bit (test_knn).
 */
#ifndef RFS_KNN_INDEX_H
#define RFS_KNN_INDEX_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_knn.h"

/// Sub-cells per grid cell side in an attached index.
#define RFS_KNN_FINE 4u
/// Sub-cells of an attached index at most.
#define RFS_KNN_FINE_CELLS (RFS_KNN_GRID * RFS_KNN_FINE * RFS_KNN_GRID * RFS_KNN_FINE)

/// A finer index over a fitted model's samples (rfs_knn_index_attach()), caller-owned,
/// about 350 KB.
typedef struct rfs_knn_index {
    /// Rebuild from the state's fitted grid (set by rfs_knn_index_attach()).
    void (*build)(rfs_knn_t *s);
    /// predict() through the index, query in cm Q24.8 (set by rfs_knn_index_attach()).
    bool (*predict)(const rfs_knn_t *s, int32_t qx_q8, int32_t qy_q8, rfs_q16_t *value);
    uint16_t start[RFS_KNN_FINE_CELLS + 1u]; ///< first entry of each sub-cell (row-major)
    rfs_sample_t pts[RFS_KNN_MAX_SAMPLES];   ///< the samples by sub-cell, x, y, rank
    uint16_t rank[RFS_KNN_MAX_SAMPLES];      ///< each one's place in rfs_knn_t.pts
    uint16_t same[RFS_KNN_MAX_SAMPLES];      ///< entries from this one on at its position
    int32_t psum_q6[RFS_KNN_MAX_SAMPLES + 1u]; ///< targets of the entries before each, Q9.6
    rfs_sample_t tmp_pts[RFS_KNN_MAX_SAMPLES]; ///< build scratch
    uint16_t tmp_rank[RFS_KNN_MAX_SAMPLES];    ///< build scratch
} rfs_knn_index_t;

/// Attach a finer index to an initialised state (NULL detaches); it is built at once when
/// a model exists, then again at the end of every fit. Predictions do not change.
void rfs_knn_index_attach(rfs_knn_t *s, rfs_knn_index_t *ix);

#endif /* RFS_KNN_INDEX_H */
