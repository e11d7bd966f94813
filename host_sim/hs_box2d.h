/* hs_box2d.h - the physical world of the simulator: walls and the robot.
 *
 * Behind this header sits Box2D 2.4 (hs_box2d.cpp is the only file that includes it).
 * Everything here is in our own types: metres, radians, seconds, doubles.
 *
 * Two kinds of static geometry are built from an lx_map_t:
 *   - collision walls: every cell that is not free (occupied OR unknown: the robot can
 *     never leave the known map), merged into rectangles;
 *   - radio walls: occupied cells only, merged the same way; they never collide and only
 *     answer ray casts (hs_box2d_walls_crossed), so a large unknown area does not count
 *     as many walls for the radio model.
 * Merging (hs_box2d_merge_rects): greedy runs along each row, then runs with the same
 * x extent on consecutive rows are merged vertically, so a 50 x 50 m map at 5 cm stays
 * at a few thousand bodies' worth of fixtures.
 *
 * The robot is a dynamic disc (TurtleBot 2 footprint, radius 0.177 m) whose velocity is
 * set every physics step from the wheel speeds (unicycle), so walls stop it while the
 * wheels keep turning (as on a real base pushing against a wall).
 */
#ifndef HS_BOX2D_H
#define HS_BOX2D_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "lx_map.h"

/// A merged axis-aligned rectangle of map cells [x0, x0 + w) x [y0, y0 + h), in cells.
typedef struct hs_rect {
    uint32_t x0; ///< first column
    uint32_t y0; ///< first row (row 0 = bottom)
    uint32_t w;  ///< columns
    uint32_t h;  ///< rows
} hs_rect_t;

/// Which cells a rectangle set covers.
typedef enum hs_box2d_kind {
    HS_BOX2D_COLLIDE = 0, ///< occupied or unknown cells
    HS_BOX2D_RADIO = 1,   ///< occupied cells only
} hs_box2d_kind_t;

/// World configuration.
typedef struct hs_box2d_cfg {
    double robot_radius_m;  ///< robot footprint radius, metres (TurtleBot 2: 0.177)
    double robot_mass_kg;   ///< robot mass, kg (TurtleBot 2 base: 6.3)
    int velocity_iters;     ///< Box2D velocity iterations (8)
    int position_iters;     ///< Box2D position iterations (3)
    double wall_merge_gap_m; ///< ray cast hits closer than this count as one wall (0.1 m)
    bool wall_pairs;        ///< the world as Box2D builds it: pairs searched among the walls
                            ///< too, the radio walls in its tree (the same world, slower;
                            ///< false: tests compare against it)
} hs_box2d_cfg_t;

/// Opaque world (owns the Box2D world).
typedef struct hs_box2d hs_box2d_t;

/// Defaults: TurtleBot 2 footprint and mass, Box2D's recommended iterations.
hs_box2d_cfg_t hs_box2d_cfg_default(void);

/// Merge the cells of `kind` into rectangles. Returns the count and a malloc'd array in
/// *out (NULL when none), or -1 when out of memory. Every covered cell is in exactly one
/// rectangle.
long hs_box2d_merge_rects(const lx_map_t *m, hs_box2d_kind_t kind, hs_rect_t **out);

/// Build the world from a map. Returns NULL with err = "reason" on failure.
hs_box2d_t *hs_box2d_create(const lx_map_t *m, const hs_box2d_cfg_t *cfg, char *err,
                            size_t errlen);

/// A map's wall rectangles of both kinds, merged once for every world built from it.
typedef struct hs_box2d_walls {
    hs_rect_t *rect[2]; ///< by hs_box2d_kind_t, malloc'd (NULL when none)
    long n[2];          ///< rectangles of each kind
} hs_box2d_walls_t;

/// Merge m's walls of both kinds into *w (hs_box2d_merge_rects). 0, or -1 when out of
/// memory (*w then holds nothing).
int hs_box2d_walls_make(const lx_map_t *m, hs_box2d_walls_t *w);

/// Free what hs_box2d_walls_make() allocated.
void hs_box2d_walls_free(hs_box2d_walls_t *w);

/// hs_box2d_create() with m's walls merged already (w from hs_box2d_walls_make(m)): the
/// same world.
hs_box2d_t *hs_box2d_create_walls(const lx_map_t *m, const hs_box2d_cfg_t *cfg,
                                  const hs_box2d_walls_t *w, char *err, size_t errlen);

/// Destroy the world (NULL is fine).
void hs_box2d_destroy(hs_box2d_t *w);

/// Return the world to the state hs_box2d_create_walls() left it in (a new robot at the
/// map origin, no contacts, the walls' tree as built), for the next run without building
/// the walls again: the same steps and contacts after it, bit for bit. 0, or -1 when the
/// world keeps wall pairs (cfg.wall_pairs; then destroy it and create another).
int hs_box2d_reset(hs_box2d_t *w);

/// Number of rectangles of each kind in the world.
long hs_box2d_rect_count(const hs_box2d_t *w, hs_box2d_kind_t kind);

/// Place the robot at (x, y) metres with heading theta radians, at rest.
void hs_box2d_place_robot(hs_box2d_t *w, double x, double y, double theta);

/// Robot pose: x, y metres, theta radians in (-pi, pi].
void hs_box2d_robot_pose(const hs_box2d_t *w, double *x, double *y, double *theta);

/// Advance by dt seconds with the robot driven at forward speed v (m/s) and turn rate
/// omega (rad/s, counter-clockwise). Walls stop it.
void hs_box2d_step(hs_box2d_t *w, double v_m_s, double omega_rad_s, double dt_s);

/// true when the robot touches a wall after the last step.
bool hs_box2d_robot_touching(const hs_box2d_t *w);

/// Wall contacts since the world was made: Box2D contact events, a touch that begins
/// while the robot touches no wall counting once.
long hs_box2d_wall_contacts(const hs_box2d_t *w);

/// Radio walls crossed by the straight segment (x0, y0)-(x1, y1), metres: the number of
/// separate runs of wall along it (ray casts in both directions; hits closer than
/// wall_merge_gap_m merged). Ends inside a wall count that wall.
unsigned hs_box2d_walls_crossed(const hs_box2d_t *w, double x0, double y0, double x1,
                                double y1);

/// hs_box2d_walls_crossed() casting every radio fixture: the same count, slower; the
/// reference its radio-fixture index is tested against.
unsigned hs_box2d_walls_crossed_all(const hs_box2d_t *w, double x0, double y0, double x1,
                                    double y1);

/// true when a disc of the robot's radius at (x, y) overlaps a collision wall or lies
/// (partly) off the map.
bool hs_box2d_disc_blocked(const hs_box2d_t *w, double x, double y);

#endif /* HS_BOX2D_H */
