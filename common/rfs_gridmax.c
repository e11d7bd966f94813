/* rfs_gridmax.c - the model's maximum over the reachable lattice (see rfs_gridmax.h). */
#include "rfs_gridmax.h"

#include "rfs_reach.h"

/* Lattice points predicted per predict_row call (stack buffer), and the side of a branch
 * and bound tile. */
#define ROW_CHUNK 16

/* What one search looks at: the map, the model and the reach bits. */
typedef struct grid_in {
    const rfs_map_t *map;
    rfs_model_t model;
    const uint8_t *reach;
} grid_in_t;

/* Full scan: row by row, in chunks, so that a model with predict_row costs one call per
 * chunk and the lattice coordinates advance by addition. The paper's greedy step takes
 * the argmax of the model over the reachable points (section 2); a point where the model
 * has no prediction (radius: no sample within the radius, scikit-learn's NaN) is skipped,
 * and the search fails only when no reachable point has one. predict_row returning false
 * means no point of its chunk has a prediction (rfs_model.h: no model). First strict
 * maximum in row-major order wins. Unreachable points are not predicted. */
static bool grid_max_scan(const grid_in_t *s, rfs_q16_t *mx, rfs_q16_t *my)
{
    const rfs_map_t *m = s->map;
    const rfs_model_ops_t *ops = s->model.ops;
    rfs_q16_t best = RFS_Q16_MIN;
    rfs_q16_t row[ROW_CHUNK];
    bool found = false;
    for (uint16_t j = 0; j < m->lh; ++j) {
        rfs_q16_t x0, py;
        rfs_map_lattice_point(m, 0, j, &x0, &py);
        uint32_t base = (uint32_t)j * m->lw;
        for (uint16_t i0 = 0; i0 < m->lw; i0 = (uint16_t)(i0 + ROW_CHUNK)) {
            uint16_t n = (uint16_t)(m->lw - i0 < ROW_CHUNK ? m->lw - i0
                                                                    : ROW_CHUNK);
            rfs_q16_t cx0 = x0 + (rfs_q16_t)i0 * m->cfg.grid;
            bool any = false;
            for (uint16_t k = 0; k < n && !any; ++k) {
                any = rfs_reach_bit(s->reach, base + i0 + k);
            }
            if (!any) {
                continue;
            }
            bool have_row = ops->predict_row != 0 &&
                            ops->predict_row(s->model.self, cx0, py, m->cfg.grid, n, row);
            if (ops->predict_row != 0 && !have_row) {
                continue;
            }
            for (uint16_t k = 0; k < n; ++k) {
                rfs_q16_t v;
                if (!rfs_reach_bit(s->reach, base + i0 + k)) {
                    continue;
                }
                if (have_row) {
                    v = row[k];
                } else if (!ops->predict(s->model.self, cx0 + (rfs_q16_t)k * m->cfg.grid, py,
                                         &v)) {
                    continue;
                }
                if (!found || v > best) {
                    best = v;
                    *mx = cx0 + (rfs_q16_t)k * m->cfg.grid;
                    *my = py;
                    found = true;
                }
            }
        }
    }
    return found;
}

/* First set bit in [from, to), or -1; whole zero bytes are skipped at once. */
static int32_t first_set(const uint8_t *b, uint32_t from, uint32_t to)
{
    uint32_t i = from;
    for (; i < to && (i & 7u) != 0u; ++i) {
        if (rfs_reach_bit(b, i)) {
            return (int32_t)i;
        }
    }
    for (; i + 8u <= to; i += 8u) {
        uint32_t v = b[i >> 3];
        if (v != 0u) {
            return (int32_t)(i + (uint32_t)__builtin_ctz(v));
        }
    }
    for (; i < to; ++i) {
        if (rfs_reach_bit(b, i)) {
            return (int32_t)i;
        }
    }
    return -1;
}

/* Last set bit in [from, to), or -1. */
static int32_t last_set(const uint8_t *b, uint32_t from, uint32_t to)
{
    uint32_t i = to;
    while (i > from && (i & 7u) != 0u) {
        --i;
        if (rfs_reach_bit(b, i)) {
            return (int32_t)i;
        }
    }
    while (i >= from + 8u) {
        uint32_t v = b[(i >> 3) - 1u];
        if (v != 0u) {
            return (int32_t)(i - 8u + (uint32_t)(31 - __builtin_clz(v)));
        }
        i -= 8u;
    }
    while (i > from) {
        --i;
        if (rfs_reach_bit(b, i)) {
            return (int32_t)i;
        }
    }
    return -1;
}

/* For a model monotone along rows (a plane), the maximum of a row's reachable points is
 * at one end; walking back from the high end over equal predictions gives the first of
 * the tied points, so the result is exactly grid_max_scan()'s. */
static bool grid_max_rows(const grid_in_t *s, int dir, rfs_q16_t *mx, rfs_q16_t *my)
{
    const rfs_map_t *m = s->map;
    const rfs_model_ops_t *ops = s->model.ops;
    rfs_q16_t best = RFS_Q16_MIN;
    bool found = false;
    for (uint16_t j = 0; j < m->lh; ++j) {
        rfs_q16_t x0, py;
        rfs_map_lattice_point(m, 0, j, &x0, &py);
        uint32_t base = (uint32_t)j * m->lw;
        int32_t first = first_set(s->reach, base, base + m->lw);
        int32_t last = first < 0 ? -1 : last_set(s->reach, base, base + m->lw);
        first = first < 0 ? -1 : first - (int32_t)base;
        last = last < 0 ? -1 : last - (int32_t)base;
        if (first < 0) {
            continue;
        }
        int32_t pick = dir > 0 ? last : first;
        rfs_q16_t v;
        if (!ops->predict(s->model.self, x0 + (rfs_q16_t)pick * m->cfg.grid, py, &v)) {
            return false;
        }
        if (dir > 0) {
            for (int32_t i = pick - 1; i >= first; --i) {
                rfs_q16_t w;
                if (!rfs_reach_bit(s->reach, base + (uint32_t)i)) {
                    continue;
                }
                if (!ops->predict(s->model.self, x0 + (rfs_q16_t)i * m->cfg.grid, py, &w) ||
                    w != v) {
                    break;
                }
                pick = i;
            }
        }
        if (!found || v > best) {
            best = v;
            *mx = x0 + (rfs_q16_t)pick * m->cfg.grid;
            *my = py;
            found = true;
        }
    }
    return found;
}

/* Branch and bound over the lattice, for a model with a bound over a box (docs/MODELS.md,
 * "Nearest neighbours"): tiles of ROW_CHUNK x ROW_CHUNK points, aligned with the full
 * scan's chunks (a tile row is one chunk), split into quadrants (see bb_node()).
 * A node is skipped when its bound cannot beat the best so far in the scan's own order
 * (bound < best, or == best and the node's first point comes after the best's), so the
 * answer is exactly grid_max_scan()'s, ties included: the first reachable point of
 * greatest prediction in row-major order, points without a prediction skipped, false
 * only when no reachable point has one. A bound that returns false promises nothing
 * (some point may have no prediction): such a node is split and its reachable points
 * are predicted one by one. The GRID_BB_SEEDS tiles whose middle point predicts highest
 * go first, to find a high maximum early; then every other tile in row-major order. No
 * memory beyond the stack (about 250 bytes). */
/* Nodes without a bound are split down to this many points (4 x 4): down to 2 x 2 costs
 * more than it saves on robot-path samples, where most small boxes near the path get no
 * radius bound either (docs/PERFORMANCE.md, "Models"). */
#define GRID_BB_LEAF 16
/* Tiles searched first. */
#define GRID_BB_SEEDS 4
/* Split depths told apart when counting bounds (tile, 8 x 8, 4 x 4, smaller). */
#define GRID_BB_DEPTHS 4u
/* Bounds at a depth stop being asked for, for the rest of the search, once this many
 * have been asked and fewer than one in four pruned its node: a radius bound is refused
 * on every box wider than twice the radius and on most boxes along a robot's path, a
 * k-neighbours bound on robot-path samples rarely prunes, and each costs a read of the
 * samples around its box (docs/PERFORMANCE.md, "Models"). */
#define GRID_BB_ASK 8u

_Static_assert(ROW_CHUNK <= 32, "one bit per tile row in a uint32_t");

typedef struct grid_bb {
    const grid_in_t *s;
    rfs_q16_t x0;      /* x of lattice column 0, metres Q16.16 */
    rfs_q16_t best;    /* best prediction so far, target units Q16.16 */
    uint32_t best_idx; /* its row-major lattice index */
    bool found;        /* best is valid */
    uint32_t asked[GRID_BB_DEPTHS];  /* bounds asked for at each split depth (0: tile) */
    uint32_t pruned[GRID_BB_DEPTHS]; /* nodes there skipped by their bound */
} grid_bb_t;

/* Lattice columns [i0, i0 + w), rows [j0, j0 + h), inside one tile whose row rj0 is bit 0
 * of the row mask (rows holding a reachable point). */
typedef struct grid_node {
    uint16_t i0, j0, w, h, rj0;
    uint16_t depth; /* splits below its tile */
} grid_node_t;

static bool bb_reach_any(const grid_in_t *s, const grid_node_t *nd)
{
    for (uint16_t j = nd->j0; j < nd->j0 + nd->h; ++j) {
        uint32_t base = (uint32_t)j * s->map->lw + nd->i0;
        if (first_set(s->reach, base, base + nd->w) >= 0) {
            return true;
        }
    }
    return false;
}

static uint32_t bb_rows(const grid_node_t *nd)
{
    uint32_t ones = nd->h >= 32u ? 0xFFFFFFFFu : (1u << nd->h) - 1u;
    return ones << (nd->j0 - nd->rj0);
}

/* The model's bound over the node, or false without asking when bounds at this depth have
 * rarely pruned in this search (GRID_BB_ASK). Not asking only costs pruning: a node
 * without a bound is searched point by point, so the answer is the same.
 * Scaling: lattice coordinates as grid_max_scan() forms them (x0 + i * grid < 2^31);
 * the counts are below the lattice's point count (< 2^32). */
static bool bb_bound(grid_bb_t *bb, const grid_node_t *nd, rfs_q16_t *ub)
{
    const rfs_map_t *m = bb->s->map;
    uint32_t d = nd->depth < GRID_BB_DEPTHS ? nd->depth : GRID_BB_DEPTHS - 1u;
    if (bb->asked[d] >= GRID_BB_ASK && bb->pruned[d] * 4u < bb->asked[d]) {
        return false;
    }
    bb->asked[d]++;
    rfs_q16_t xa, ya, xb, yb;
    rfs_map_lattice_point(m, 0, nd->j0, &xa, &ya);
    rfs_map_lattice_point(m, 0, (uint16_t)(nd->j0 + nd->h - 1u), &xb, &yb);
    xa = bb->x0 + (rfs_q16_t)nd->i0 * m->cfg.grid;
    xb = bb->x0 + (rfs_q16_t)(nd->i0 + nd->w - 1u) * m->cfg.grid;
    return bb->s->model.ops->bound(bb->s->model.self, xa, ya, xb, yb, ub);
}

static bool bb_prunable(grid_bb_t *bb, const grid_node_t *nd, rfs_q16_t ub)
{
    uint32_t first = (uint32_t)nd->j0 * bb->s->map->lw + nd->i0;
    bool skip = bb->found && (ub < bb->best || (ub == bb->best && first > bb->best_idx));
    bb->pruned[nd->depth < GRID_BB_DEPTHS ? nd->depth : GRID_BB_DEPTHS - 1u] += skip;
    return skip;
}

static void bb_consider(grid_bb_t *bb, rfs_q16_t v, uint32_t idx)
{
    if (!bb->found || v > bb->best || (v == bb->best && idx < bb->best_idx)) {
        bb->best = v;
        bb->best_idx = idx;
        bb->found = true;
    }
}

/* Predict the node's reachable points and take those with a prediction as candidates.
 * A model with predict_row gets the scan's very call (the whole chunk), so the values are
 * the scan's bit for bit; false from it skips the row as the scan skips the chunk. */
static void bb_leaf(grid_bb_t *bb, const grid_node_t *nd, uint32_t rmask)
{
    const grid_in_t *s = bb->s;
    const rfs_map_t *m = s->map;
    const rfs_model_ops_t *ops = s->model.ops;
    rfs_q16_t row[ROW_CHUNK];
    uint16_t c0 = (uint16_t)(nd->i0 - nd->i0 % ROW_CHUNK);
    uint16_t cn = (uint16_t)(m->lw - c0 < ROW_CHUNK ? m->lw - c0 : ROW_CHUNK);
    for (uint16_t j = nd->j0; j < nd->j0 + nd->h; ++j) {
        uint32_t base = (uint32_t)j * m->lw;
        if (((rmask >> (j - nd->rj0)) & 1u) == 0u ||
            first_set(s->reach, base + nd->i0, base + nd->i0 + nd->w) < 0) {
            continue;
        }
        rfs_q16_t x, py;
        rfs_map_lattice_point(m, 0, j, &x, &py);
        if (ops->predict_row != 0 &&
            !ops->predict_row(s->model.self, bb->x0 + (rfs_q16_t)c0 * m->cfg.grid, py,
                              m->cfg.grid, cn, row)) {
            continue;
        }
        for (uint16_t i = nd->i0; i < nd->i0 + nd->w; ++i) {
            rfs_q16_t v;
            if (!rfs_reach_bit(s->reach, base + i)) {
                continue;
            }
            if (ops->predict_row != 0) {
                v = row[i - c0];
            } else if (!ops->predict(s->model.self, bb->x0 + (rfs_q16_t)i * m->cfg.grid, py,
                                     &v)) {
                continue;
            }
            bb_consider(bb, v, base + i);
        }
    }
}

/* Search a node holding reachable points; own: the node's own bound promised predictions
 * over it (and did not prune it). A node with its own bound is scanned whole: splitting it
 * costs four bounds, each several predictions' work, and on robot-path samples (dense,
 * noisy) the children's bounds rarely prune (docs/PERFORMANCE.md, "Models"). A node
 * without one (radius: a sample may not cover it) is split down to GRID_BB_LEAF points,
 * where smaller boxes can be covered. Children without a reachable point are dropped
 * before their bound is asked; children with a bound go highest first (the tie rule does
 * not depend on the order). */
static void bb_node(grid_bb_t *bb, const grid_node_t *nd, uint32_t rmask, bool own)
{
    if (own || (uint32_t)nd->w * nd->h <= GRID_BB_LEAF) {
        bb_leaf(bb, nd, rmask);
        return;
    }
    uint16_t hw = (uint16_t)((nd->w + 1u) / 2u), hh = (uint16_t)((nd->h + 1u) / 2u);
    grid_node_t ch[4];
    rfs_q16_t ub[4];
    bool ok[4];
    uint32_t order[4] = {0u, 0u, 0u, 0u}, n = 0; /* filled in insertion order below */
    for (uint32_t q = 0; q < 4u; ++q) {
        grid_node_t c = *nd;
        c.i0 = (uint16_t)(nd->i0 + ((q & 1u) ? hw : 0u));
        c.w = (uint16_t)((q & 1u) ? nd->w - hw : hw);
        c.j0 = (uint16_t)(nd->j0 + ((q & 2u) ? hh : 0u));
        c.h = (uint16_t)((q & 2u) ? nd->h - hh : hh);
        c.depth = (uint16_t)(nd->depth + 1u);
        if (c.w == 0u || c.h == 0u || (rmask & bb_rows(&c)) == 0u ||
            !bb_reach_any(bb->s, &c)) {
            continue;
        }
        ok[q] = bb_bound(bb, &c, &ub[q]);
        ch[q] = c;
        uint32_t at = n++;
        while (at > 0u && ok[q] &&
               (!ok[order[at - 1u]] || ub[order[at - 1u]] < ub[q])) {
            order[at] = order[at - 1u];
            --at;
        }
        order[at] = q;
    }
    for (uint32_t k = 0; k < n; ++k) {
        uint32_t q = order[k];
        if (ok[q] && bb_prunable(bb, &ch[q], ub[q])) {
            continue;
        }
        bb_node(bb, &ch[q], rmask, ok[q]);
    }
}

/* Tile (ti, tj) and its row mask: bit r set when chunk row r holds a reachable point. */
static uint32_t bb_tile(const grid_in_t *s, uint16_t ti, uint16_t tj, grid_node_t *nd)
{
    const rfs_map_t *m = s->map;
    nd->i0 = (uint16_t)(ti * ROW_CHUNK);
    nd->j0 = (uint16_t)(tj * ROW_CHUNK);
    nd->rj0 = nd->j0;
    nd->depth = 0u;
    nd->w = (uint16_t)(m->lw - nd->i0 < ROW_CHUNK ? m->lw - nd->i0 : ROW_CHUNK);
    nd->h = (uint16_t)(m->lh - nd->j0 < ROW_CHUNK ? m->lh - nd->j0 : ROW_CHUNK);
    uint32_t rmask = 0u;
    for (uint16_t r = 0; r < nd->h; ++r) {
        uint32_t base = (uint32_t)(nd->j0 + r) * m->lw + nd->i0;
        if (first_set(s->reach, base, base + nd->w) >= 0) {
            rmask |= 1u << r;
        }
    }
    return rmask;
}

static bool grid_max_bb(const grid_in_t *s, rfs_q16_t *mx, rfs_q16_t *my)
{
    const rfs_map_t *m = s->map;
    grid_bb_t bb = {.s = s, .best = RFS_Q16_MIN, .best_idx = 0u, .found = false};
    rfs_q16_t py;
    rfs_map_lattice_point(m, 0, 0, &bb.x0, &py);
    uint16_t tw = (uint16_t)((m->lw + ROW_CHUNK - 1u) / ROW_CHUNK);
    uint16_t th = (uint16_t)((m->lh + ROW_CHUNK - 1u) / ROW_CHUNK);
    uint32_t seed[GRID_BB_SEEDS]; /* tile numbers, highest bound first */
    rfs_q16_t seed_ub[GRID_BB_SEEDS];
    uint32_t ns = 0;
    grid_node_t nd;
    rfs_q16_t ub;
    for (uint32_t t = 0; t < (uint32_t)tw * th; ++t) {
        uint32_t rmask = bb_tile(s, (uint16_t)(t % tw), (uint16_t)(t / tw), &nd);
        if (rmask == 0u) {
            continue;
        }
        /* Seeds by the prediction at the tile's middle point (a bound costs more); a
         * middle point without one makes no seed (the tile is searched in order). */
        uint16_t mi = (uint16_t)(nd.i0 + nd.w / 2u), mj = (uint16_t)(nd.j0 + nd.h / 2u);
        rfs_q16_t cx, cy;
        rfs_map_lattice_point(m, 0, mj, &cx, &cy);
        cx = bb.x0 + (rfs_q16_t)mi * m->cfg.grid;
        if (!s->model.ops->predict(s->model.self, cx, cy, &ub)) {
            continue;
        }
        if (ns == GRID_BB_SEEDS && ub <= seed_ub[ns - 1u]) {
            continue;
        }
        uint32_t at = ns < GRID_BB_SEEDS ? ns++ : ns - 1u;
        while (at > 0u && seed_ub[at - 1u] < ub) {
            seed[at] = seed[at - 1u];
            seed_ub[at] = seed_ub[at - 1u];
            --at;
        }
        seed[at] = t;
        seed_ub[at] = ub;
    }
    for (uint32_t k = 0; k < ns; ++k) {
        uint32_t rmask = bb_tile(s, (uint16_t)(seed[k] % tw), (uint16_t)(seed[k] / tw), &nd);
        bool ok = bb_bound(&bb, &nd, &ub);
        if (!ok || !bb_prunable(&bb, &nd, ub)) {
            bb_node(&bb, &nd, rmask, ok);
        }
    }
    for (uint32_t t = 0; t < (uint32_t)tw * th; ++t) {
        bool seeded = false;
        for (uint32_t k = 0; k < ns; ++k) {
            seeded = seeded || seed[k] == t;
        }
        uint32_t rmask = bb_tile(s, (uint16_t)(t % tw), (uint16_t)(t / tw), &nd);
        if (seeded || rmask == 0u) {
            continue;
        }
        bool ok = bb_bound(&bb, &nd, &ub);
        if (ok && bb_prunable(&bb, &nd, ub)) {
            continue;
        }
        bb_node(&bb, &nd, rmask, ok);
    }
    if (bb.found) {
        uint16_t i = (uint16_t)(bb.best_idx % m->lw), j = (uint16_t)(bb.best_idx / m->lw);
        rfs_map_lattice_point(m, 0, j, mx, my);
        *mx = bb.x0 + (rfs_q16_t)i * m->cfg.grid;
    }
    return bb.found;
}


bool rfs_gridmax_find(const rfs_map_t *map, const rfs_model_t *model, const uint8_t *reach,
                      rfs_q16_t *mx, rfs_q16_t *my)
{
    const grid_in_t in = { map, *model, reach };
    const rfs_model_ops_t *ops = model->ops;
    if (ops->row_monotone != 0) {
        return grid_max_rows(&in, ops->row_monotone(model->self), mx, my);
    }
    if (ops->bound != 0) {
        return grid_max_bb(&in, mx, my);
    }
    return grid_max_scan(&in, mx, my);
}

bool rfs_gridmax_scan(const rfs_map_t *map, const rfs_model_t *model, const uint8_t *reach,
                      rfs_q16_t *mx, rfs_q16_t *my)
{
    const grid_in_t in = { map, *model, reach };
    return grid_max_scan(&in, mx, my);
}
