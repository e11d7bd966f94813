/* rfs_gridmax.h - the model's maximum over the reachable lattice: the greedy step's grid
 * search (paper section 2: "go towards the model's maximum").
 *
 * The answer is the first reachable lattice point of greatest prediction in row-major
 * order (first strict maximum); points where the model has no prediction (radius: no
 * sample within the radius, scikit-learn's NaN) are skipped, and the search fails only
 * when no reachable point has one. rfs_gridmax_find() takes the model's shortcuts: the
 * row ends for a model monotone along rows (row_monotone), branch and bound over 16 x 16
 * tiles for a model with a bound over a box (bound); either gives exactly the full
 * scan's answer, ties included (docs/PERFORMANCE.md, "Models"). No memory beyond the
 * stack (about 250 bytes).
 */
#ifndef RFS_GRIDMAX_H
#define RFS_GRIDMAX_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_map.h"
#include "rfs_model.h"

/// The model's maximum over the lattice points set in `reach` (one bit per lattice
/// point, rfs_reach.h), by the fastest search the model allows; (mx, my) metres Q16.16.
/// false when no such point has a prediction (no model, no reachable point).
/// Scaling and overflow: lattice coordinates x0 + i * grid, Q16.16, stay below 2^31 on
/// any map rfs_map_init accepts; predictions are only compared, never combined.
bool rfs_gridmax_find(const rfs_map_t *map, const rfs_model_t *model, const uint8_t *reach,
                      rfs_q16_t *mx, rfs_q16_t *my);

/// The same search by predicting every reachable point (the reference for the shortcuts).
bool rfs_gridmax_scan(const rfs_map_t *map, const rfs_model_t *model, const uint8_t *reach,
                      rfs_q16_t *mx, rfs_q16_t *my);

#endif /* RFS_GRIDMAX_H */
