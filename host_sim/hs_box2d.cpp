/* hs_box2d.cpp - the Box2D 2.4 adapter behind hs_box2d.h (the only file including Box2D).
 *
 * Geometry: the map frame, metres, as in lx_map_t. Walls are static fixtures on two
 * static bodies (collision and radio); the robot is a dynamic circle whose velocity is
 * set before every step (unicycle from the wheel speeds, see hs_box2d.h).
 */
#include <box2d/box2d.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <utility>
#include <vector>

extern "C" {
#include "hs_box2d.h"
}

namespace {
struct ForgetWallMoves {}; // UpdatePairs' tag below
}

/* The walls' proxies need no pair search: Box2D buffers every new proxy as moved and its
 * first Step queries each against the tree, to find pairs of two static bodies that it
 * then drops (b2ContactManager::AddPair: not dynamic), all the robot's pairs coming from
 * the robot's own query (a proxy skips moved ones above its id). Forgetting the walls'
 * moves once they are built, their moved flags cleared as that Step would, leaves the
 * robot's pairs, their order and so every contact as they were, without the O(walls)
 * queries (most of the first Step on a large floor). An explicit specialisation of the
 * public member template, so a member of b2BroadPhase. */
template <>
void b2BroadPhase::UpdatePairs<ForgetWallMoves>(ForgetWallMoves *)
{
    for (int32 i = 0; i < m_moveCount; ++i) {
        if (m_moveBuffer[i] != e_nullProxy) {
            m_tree.ClearMoved(m_moveBuffer[i]);
        }
    }
    m_moveCount = 0;
}

namespace {
/* The broad phase as the walls left it (hs_box2d_reset): its tree's arrays and counts. A
 * run's robot proxy moves by removal and insertion, whose rotations reshape the walls'
 * branches; the tree's shape orders the robot's pairs and so its contacts. */
struct TreeState {
    std::vector<b2TreeNode> nodes; // the whole node array (free nodes too: the free list)
    int32 root = b2_nullNode, count = 0, capacity = 0, free_list = b2_nullNode, insertions = 0;
    int32 proxies = 0; // the broad phase's proxy count
    bool save = true;  // true: copy the tree into this; false: copy this into the tree
};
using InvDt0 = float b2World::*;
InvDt0 world_inv_dt0();
/* b2World::m_inv_dt0 (the last step's 1/dt, 0 in a new world) has no accessor: an
 * explicit instantiation may name a private member ([temp.spec]), and hands it out. */
template <InvDt0 M> struct InvDt0Of {
    friend InvDt0 world_inv_dt0() { return M; }
};
template struct InvDt0Of<&b2World::m_inv_dt0>;
} // namespace

/* TreeState's copy, as a member of b2DynamicTree (an explicit specialisation of its public
 * template, like UpdatePairs below): const only in its signature. */
template <>
void b2DynamicTree::Query<TreeState>(TreeState *s, const b2AABB &) const
{
    b2DynamicTree *t = const_cast<b2DynamicTree *>(this);
    if (s->save) {
        s->nodes.assign(m_nodes, m_nodes + m_nodeCapacity);
        s->root = m_root;
        s->count = m_nodeCount;
        s->capacity = m_nodeCapacity;
        s->free_list = m_freeList;
        s->insertions = m_insertionCount;
        return;
    }
    // Capacity only grows: the live array holds the saved one (a smaller capacity only
    // means the next growth comes sooner, as in the new tree).
    b2Assert(m_nodeCapacity >= s->capacity);
    std::copy(s->nodes.begin(), s->nodes.end(), t->m_nodes);
    t->m_root = s->root;
    t->m_nodeCount = s->count;
    t->m_nodeCapacity = s->capacity;
    t->m_freeList = s->free_list;
    t->m_insertionCount = s->insertions;
}

/* TreeState with the broad phase's counts (no moves buffered: the walls' are forgotten). */
template <>
void b2BroadPhase::UpdatePairs<TreeState>(TreeState *s)
{
    if (s->save) {
        s->proxies = m_proxyCount;
    } else {
        m_proxyCount = s->proxies;
        m_moveCount = 0;
        m_pairCount = 0;
    }
    m_tree.Query(s, b2AABB());
}

namespace {

constexpr uint16 CAT_COLLIDE = 0x0001; // walls the robot collides with
constexpr uint16 CAT_RADIO = 0x0002;   // walls the radio counts; never collide
constexpr uint16 CAT_ROBOT = 0x0004;

bool cell_in(const lx_map_t *m, uint32_t x, uint32_t y, hs_box2d_kind_t kind)
{
    uint8_t c = m->cell[(size_t)y * m->w + x];
    return kind == HS_BOX2D_RADIO ? c == LX_CELL_OCC : c != LX_CELL_FREE;
}

// Per radio fixture a ray hits, the fraction at which it enters.
struct HitCollector {
    std::vector<std::pair<b2Fixture *, float>> hits;
};

/// Counts the robot's wall contacts from Box2D's contact events: a contact begins when
/// the robot touches a wall while touching none (scraping along several wall rectangles
/// is one contact).
class ContactCounter : public b2ContactListener {
public:
    long touching = 0; // wall fixtures the robot touches now
    long contacts = 0; // contacts begun
    void BeginContact(b2Contact *c) override
    {
        if (c->IsTouching() && touching++ == 0) {
            contacts++;
        }
    }
    void EndContact(b2Contact *c) override
    {
        (void)c;
        if (touching > 0) {
            touching--;
        }
    }
};

} // namespace

struct hs_box2d {
    hs_box2d_cfg_t cfg;
    b2World *world;
    b2Body *robot;
    ContactCounter contacts;
    long n_collide;
    long n_radio;
    uint32_t w, h;
    double res, ox, oy;
    std::vector<uint8_t> cell; // copy of the map cells (for disc_blocked)
    // Free-space cache for the fast path of hs_box2d_step: per CLEAR_M cell, 1 when a
    // disc of radius + CLEAR_MARGIN anywhere in it touches nothing, 0 when it may,
    // -1 not yet known.
    mutable std::vector<int8_t> clear;
    uint32_t cw, ch;
    // Radio fixtures by RAY_CELL_M cell of the map (every cell their box, widened by
    // RAY_MARGIN_M, touches): first[c] .. first[c + 1] - 1 index into fx_of.
    std::vector<b2Fixture *> radio_fx;
    std::vector<uint32_t> first, fx_of;
    uint32_t rw, rh;
    mutable std::vector<uint32_t> seen; // per radio fixture: the last cast that tested it
    mutable uint32_t casts;
    std::vector<double> radio_box; // per radio fixture: its AABB's centre x, y, half width, height
    mutable HitCollector fwd, rev;  // walls_crossed's hits and intervals, kept for their capacity
    mutable std::vector<std::pair<double, double>> iv;
    TreeState built; // the broad phase before the robot (hs_box2d_reset); unused with wall_pairs
};

namespace {
constexpr double CLEAR_M = 0.1;       // cache cell, metres
constexpr double CLEAR_MARGIN = 0.05; // > one step of travel (0.7 m/s x 20 ms) plus Box2D's skin
constexpr double RAY_CELL_M = 0.5;    // cell of the radio fixtures' index, metres
constexpr double RAY_MARGIN_M = 0.05; // far above float rounding: no hit is left out
constexpr double RAY_MISS_M = 1e-3;   // a segment this far from a box (beyond its AABB's
                                      // polygon radius) misses it in float too
}

extern "C" hs_box2d_cfg_t hs_box2d_cfg_default(void)
{
    hs_box2d_cfg_t c;
    c.robot_radius_m = 0.177; // TurtleBot 2 (Kobuki) footprint radius, turtlebot_navigation
    c.robot_mass_kg = 6.3;    // Kobuki base mass, vendor data sheet
    c.velocity_iters = 8;     // Box2D manual's recommendation
    c.position_iters = 3;
    c.wall_merge_gap_m = 0.1;
    c.wall_pairs = false;
    return c;
}

extern "C" long hs_box2d_merge_rects(const lx_map_t *m, hs_box2d_kind_t kind, hs_rect_t **out)
{
    *out = nullptr;
    std::vector<hs_rect_t> done;
    std::vector<hs_rect_t> open; // rectangles that end at the previous row, sorted by x0
    std::vector<hs_rect_t> next;
    try {
        for (uint32_t y = 0; y < m->h; y++) {
            next.clear();
            size_t oi = 0;
            uint32_t x = 0;
            while (x < m->w) {
                if (!cell_in(m, x, y, kind)) {
                    x++;
                    continue;
                }
                uint32_t x0 = x;
                while (x < m->w && cell_in(m, x, y, kind)) {
                    x++;
                }
                uint32_t wdt = x - x0;
                // Open rectangles left of this run can no longer continue.
                while (oi < open.size() && open[oi].x0 < x0) {
                    done.push_back(open[oi++]);
                }
                if (oi < open.size() && open[oi].x0 == x0 && open[oi].w == wdt) {
                    hs_rect_t r = open[oi++];
                    r.h++;
                    next.push_back(r);
                } else {
                    next.push_back(hs_rect_t{x0, y, wdt, 1});
                }
            }
            while (oi < open.size()) {
                done.push_back(open[oi++]);
            }
            open.swap(next);
        }
        for (const hs_rect_t &r : open) {
            done.push_back(r);
        }
    } catch (const std::bad_alloc &) {
        return -1;
    }
    if (done.empty()) {
        return 0;
    }
    hs_rect_t *a = static_cast<hs_rect_t *>(malloc(done.size() * sizeof(hs_rect_t)));
    if (!a) {
        return -1;
    }
    memcpy(a, done.data(), done.size() * sizeof(hs_rect_t));
    *out = a;
    return (long)done.size();
}

static long add_walls(const lx_map_t *m, b2Body *body, hs_box2d_kind_t kind,
                      const hs_rect_t *rects, long n)
{
    for (long i = 0; i < n; i++) {
        const hs_rect_t &r = rects[i];
        float hx = (float)(0.5 * r.w * m->res);
        float hy = (float)(0.5 * r.h * m->res);
        b2Vec2 c((float)(m->origin_x + (r.x0 + 0.5 * r.w) * m->res),
                 (float)(m->origin_y + (r.y0 + 0.5 * r.h) * m->res));
        b2PolygonShape box;
        box.SetAsBox(hx, hy, c, 0.0f);
        b2FixtureDef fd;
        fd.shape = &box;
        fd.friction = 0.0f;
        if (kind == HS_BOX2D_RADIO) {
            fd.isSensor = true;
            fd.filter.categoryBits = CAT_RADIO;
            fd.filter.maskBits = 0; // answers ray casts only
        } else {
            fd.filter.categoryBits = CAT_COLLIDE;
            fd.filter.maskBits = CAT_ROBOT;
        }
        body->CreateFixture(&fd);
    }
    return n;
}

extern "C" int hs_box2d_walls_make(const lx_map_t *m, hs_box2d_walls_t *w)
{
    for (int k = 0; k < 2; k++) {
        w->rect[k] = nullptr;
        w->n[k] = hs_box2d_merge_rects(m, (hs_box2d_kind_t)k, &w->rect[k]);
        if (w->n[k] < 0) {
            hs_box2d_walls_free(w);
            return -1;
        }
    }
    return 0;
}

extern "C" void hs_box2d_walls_free(hs_box2d_walls_t *w)
{
    for (int k = 0; k < 2; k++) {
        free(w->rect[k]);
        w->rect[k] = nullptr;
        w->n[k] = 0;
    }
}

/* Cells of the radio index the box [x0, x1] x [y0, y1] (metres) touches, clamped. */
static void ray_cells(const hs_box2d_t *w, double x0, double y0, double x1, double y1,
                      uint32_t *i0, uint32_t *j0, uint32_t *i1, uint32_t *j1)
{
    auto cell = [](double v, uint32_t n) {
        double c = std::floor(v / RAY_CELL_M);
        return c < 0.0 ? 0u : (c >= (double)n ? n - 1u : (uint32_t)c);
    };
    *i0 = cell(x0 - w->ox, w->rw);
    *i1 = cell(x1 - w->ox, w->rw);
    *j0 = cell(y0 - w->oy, w->rh);
    *j1 = cell(y1 - w->oy, w->rh);
}

/* The radio fixtures by cell (hs_box2d_walls_crossed tests only those of the cells along
 * its segment instead of walking Box2D's tree, twice). */
static void index_radio(hs_box2d_t *w, b2Body *radio)
{
    w->rw = (uint32_t)std::ceil(w->w * w->res / RAY_CELL_M);
    w->rh = (uint32_t)std::ceil(w->h * w->res / RAY_CELL_M);
    for (b2Fixture *f = radio->GetFixtureList(); f; f = f->GetNext()) {
        w->radio_fx.push_back(f);
    }
    std::vector<uint32_t> count((size_t)w->rw * w->rh + 1u, 0u);
    w->radio_box.resize(4 * w->radio_fx.size());
    for (int pass = 0; pass < 2; pass++) {
        for (size_t k = 0; k < w->radio_fx.size(); k++) {
            b2AABB bb;
            w->radio_fx[k]->GetShape()->ComputeAABB(&bb, radio->GetTransform(), 0);
            double *box = &w->radio_box[4 * k];
            box[0] = 0.5 * ((double)bb.lowerBound.x + bb.upperBound.x);
            box[1] = 0.5 * ((double)bb.lowerBound.y + bb.upperBound.y);
            box[2] = 0.5 * ((double)bb.upperBound.x - bb.lowerBound.x);
            box[3] = 0.5 * ((double)bb.upperBound.y - bb.lowerBound.y);
            uint32_t i0, j0, i1, j1;
            ray_cells(w, bb.lowerBound.x - RAY_MARGIN_M, bb.lowerBound.y - RAY_MARGIN_M,
                      bb.upperBound.x + RAY_MARGIN_M, bb.upperBound.y + RAY_MARGIN_M, &i0, &j0,
                      &i1, &j1);
            for (uint32_t j = j0; j <= j1; j++) {
                for (uint32_t i = i0; i <= i1; i++) {
                    size_t c = (size_t)j * w->rw + i;
                    if (pass == 0) {
                        count[c + 1u]++;
                    } else {
                        w->fx_of[count[c]++] = (uint32_t)k;
                    }
                }
            }
        }
        if (pass == 0) {
            for (size_t c = 1; c < count.size(); c++) {
                count[c] += count[c - 1u];
            }
            w->first = count;
            w->fx_of.assign(count.back(), 0u);
        }
    }
    w->seen.assign(w->radio_fx.size(), 0u);
    w->casts = 0u;
}

extern "C" hs_box2d_t *hs_box2d_create(const lx_map_t *m, const hs_box2d_cfg_t *cfg, char *err,
                                       size_t errlen)
{
    // An unusable map gets no walls: hs_box2d_create_walls() rejects it.
    const bool usable = m && m->cell && m->w > 0 && m->h > 0 && m->res > 0.0;
    hs_box2d_walls_t walls = {{nullptr, nullptr}, {0, 0}};
    if (usable && hs_box2d_walls_make(m, &walls) != 0) {
        snprintf(err, errlen, "world: out of memory");
        return nullptr;
    }
    hs_box2d_t *w = hs_box2d_create_walls(m, cfg, &walls, err, errlen);
    hs_box2d_walls_free(&walls);
    return w;
}

/* The robot: a dynamic disc at the map origin, colliding with the collision walls only. */
static void add_robot(hs_box2d_t *w)
{
    const hs_box2d_cfg_t &c = w->cfg;
    b2BodyDef bd;
    bd.type = b2_dynamicBody;
    bd.position.Set((float)w->ox, (float)w->oy);
    w->robot = w->world->CreateBody(&bd);
    b2CircleShape disc;
    disc.m_radius = (float)c.robot_radius_m;
    b2FixtureDef fd;
    fd.shape = &disc;
    fd.density = (float)(c.robot_mass_kg / (M_PI * c.robot_radius_m * c.robot_radius_m));
    fd.friction = 0.0f;
    fd.filter.categoryBits = CAT_ROBOT;
    fd.filter.maskBits = CAT_COLLIDE;
    w->robot->CreateFixture(&fd);
}

extern "C" hs_box2d_t *hs_box2d_create_walls(const lx_map_t *m, const hs_box2d_cfg_t *cfg,
                                             const hs_box2d_walls_t *walls, char *err,
                                             size_t errlen)
{
    hs_box2d_cfg_t c = cfg ? *cfg : hs_box2d_cfg_default();
    if (!(c.robot_radius_m > 0.0) || !(c.robot_mass_kg > 0.0) || c.velocity_iters < 1 ||
        c.position_iters < 1 || !(c.wall_merge_gap_m >= 0.0)) {
        snprintf(err, errlen, "world: robot radius, mass and solver iterations must be positive");
        return nullptr;
    }
    if (!m || !m->cell || m->w == 0 || m->h == 0 || !(m->res > 0.0)) {
        snprintf(err, errlen, "world: empty map");
        return nullptr;
    }
    hs_box2d_t *w = new (std::nothrow) hs_box2d();
    if (!w) {
        snprintf(err, errlen, "world: out of memory");
        return nullptr;
    }
    try {
        w->cfg = c;
        w->w = m->w;
        w->h = m->h;
        w->res = m->res;
        w->ox = m->origin_x;
        w->oy = m->origin_y;
        w->cell.assign(m->cell, m->cell + (size_t)m->w * m->h);
        w->cw = (uint32_t)std::ceil(m->w * m->res / CLEAR_M);
        w->ch = (uint32_t)std::ceil(m->h * m->res / CLEAR_M);
        w->clear.assign((size_t)w->cw * w->ch, -1);
        w->world = new b2World(b2Vec2(0.0f, 0.0f));
        // No time-of-impact sub-stepping: at 0.7 m/s and 50 Hz the robot moves 1.4 cm per
        // step, far less than the thinnest wall (one 5 cm cell), so it cannot tunnel.
        w->world->SetContinuousPhysics(false);
        w->world->SetContactListener(&w->contacts);
        b2BodyDef sd;
        sd.type = b2_staticBody;
        b2Body *collide = w->world->CreateBody(&sd);
        // The radio walls answer ray casts through their own index (index_radio), never
        // Box2D's tree or contacts: on a disabled body (unless wall_pairs) their fixtures
        // get no broad-phase proxies, a tree half the size to build every run (the robot's
        // contacts, with the collision walls only, come in the same order).
        sd.enabled = c.wall_pairs;
        b2Body *radio = w->world->CreateBody(&sd);
        w->n_collide = add_walls(m, collide, HS_BOX2D_COLLIDE, walls->rect[HS_BOX2D_COLLIDE],
                                 walls->n[HS_BOX2D_COLLIDE]);
        w->n_radio = add_walls(m, radio, HS_BOX2D_RADIO, walls->rect[HS_BOX2D_RADIO],
                               walls->n[HS_BOX2D_RADIO]);
        index_radio(w, radio);
        if (!c.wall_pairs) {
            ForgetWallMoves tag;
            b2BroadPhase &bp =
                const_cast<b2ContactManager &>(w->world->GetContactManager()).m_broadPhase;
            bp.UpdatePairs(&tag);
            bp.UpdatePairs(&w->built);
        }
        add_robot(w);
    } catch (const std::bad_alloc &) {
        hs_box2d_destroy(w);
        snprintf(err, errlen, "world: out of memory");
        return nullptr;
    }
    return w;
}

extern "C" void hs_box2d_destroy(hs_box2d_t *w)
{
    if (!w) {
        return;
    }
    delete w->world;
    delete w;
}

/* What a run changes: the robot (body, fixture, proxy, contacts), the tree round its
 * proxy, the broad phase's counts and move buffer, the world's last 1/dt and the contact
 * counts. The walls, their fixtures and proxies never move; the free-space cache and the
 * radio index depend on the walls alone. The robot is made again, as hs_box2d_create_walls
 * makes it, after the tree is back: the same proxy and node ids, body list and pairs. */
extern "C" int hs_box2d_reset(hs_box2d_t *w)
{
    if (w->cfg.wall_pairs) {
        return -1; // the walls' moves stay buffered until the first step: not saved
    }
    w->world->DestroyBody(w->robot); // its contacts end: EndContact may count down
    w->robot = nullptr;
    b2BroadPhase &bp = const_cast<b2ContactManager &>(w->world->GetContactManager()).m_broadPhase;
    w->built.save = false;
    bp.UpdatePairs(&w->built);
    w->built.save = true;
    w->world->*world_inv_dt0() = 0.0f;
    w->contacts.touching = 0;
    w->contacts.contacts = 0;
    add_robot(w);
    return 0;
}

extern "C" long hs_box2d_rect_count(const hs_box2d_t *w, hs_box2d_kind_t kind)
{
    return kind == HS_BOX2D_RADIO ? w->n_radio : w->n_collide;
}

extern "C" void hs_box2d_place_robot(hs_box2d_t *w, double x, double y, double theta)
{
    w->robot->SetTransform(b2Vec2((float)x, (float)y), (float)theta);
    w->robot->SetLinearVelocity(b2Vec2(0.0f, 0.0f));
    w->robot->SetAngularVelocity(0.0f);
    w->robot->SetAwake(true);
}

extern "C" void hs_box2d_robot_pose(const hs_box2d_t *w, double *x, double *y, double *theta)
{
    b2Vec2 p = w->robot->GetPosition();
    double a = w->robot->GetAngle(); // kept within +-100 rad by hs_box2d_step
    while (a > M_PI) {
        a -= 2.0 * M_PI;
    }
    while (a <= -M_PI) {
        a += 2.0 * M_PI;
    }
    *x = p.x;
    *y = p.y;
    *theta = a;
}

/// true when no wall can be within CLEAR_MARGIN of the robot anywhere in its cache cell.
static bool disc_blocked_r(const hs_box2d_t *w, double x, double y, double r);

static bool robot_clear(const hs_box2d_t *w)
{
    b2Vec2 p = w->robot->GetPosition();
    double fx = (p.x - w->ox) / CLEAR_M, fy = (p.y - w->oy) / CLEAR_M;
    if (!(fx >= 0.0 && fy >= 0.0 && fx < w->cw && fy < w->ch)) {
        return false;
    }
    size_t i = (size_t)fy * w->cw + (size_t)fx;
    if (w->clear[i] < 0) {
        // Disc around the cache cell's centre covering every position in the cell.
        double cx = w->ox + ((size_t)fx + 0.5) * CLEAR_M, cy = w->oy + ((size_t)fy + 0.5) * CLEAR_M;
        double r = w->cfg.robot_radius_m + CLEAR_MARGIN + CLEAR_M * M_SQRT1_2;
        w->clear[i] = disc_blocked_r(w, cx, cy, r) ? 0 : 1;
    }
    return w->clear[i] == 1;
}

extern "C" void hs_box2d_step(hs_box2d_t *w, double v_m_s, double omega_rad_s, double dt_s)
{
    float a = w->robot->GetAngle();
    if (std::fabs(v_m_s) * dt_s < CLEAR_MARGIN && robot_clear(w)) {
        // Fast path far from walls: nothing can collide within this step, so integrate
        // the unicycle as Box2D's own integrator would (semi-implicit Euler with the
        // velocity set from the heading at the start of the step).
        b2Vec2 p = w->robot->GetPosition();
        b2Vec2 vel((float)(v_m_s * std::cos(a)), (float)(v_m_s * std::sin(a)));
        b2Vec2 np = p + (float)dt_s * vel;
        float na = a + (float)(dt_s * omega_rad_s);
        if (na > 10.0f || na < -10.0f) {
            na = (float)std::remainder((double)na, 2.0 * M_PI);
        }
        w->robot->SetTransform(np, na);
        w->robot->SetLinearVelocity(vel);
        w->robot->SetAngularVelocity((float)omega_rad_s);
        return;
    }
    w->robot->SetLinearVelocity(
        b2Vec2((float)(v_m_s * std::cos(a)), (float)(v_m_s * std::sin(a))));
    w->robot->SetAngularVelocity((float)omega_rad_s);
    w->robot->SetAwake(true);
    w->world->Step((float)dt_s, w->cfg.velocity_iters, w->cfg.position_iters);
    // Keep the heading bounded so float precision does not decay over a long run.
    float ang = w->robot->GetAngle();
    if (ang > 10.0f || ang < -10.0f) {
        w->robot->SetTransform(w->robot->GetPosition(),
                               (float)std::remainder((double)ang, 2.0 * M_PI));
    }
}

extern "C" bool hs_box2d_robot_touching(const hs_box2d_t *w)
{
    if (robot_clear(w)) {
        return false; // contacts are not updated on the fast path; none can touch here
    }
    for (b2ContactEdge *e = w->robot->GetContactList(); e; e = e->next) {
        if (e->contact->IsTouching()) {
            return true;
        }
    }
    return false;
}

extern "C" long hs_box2d_wall_contacts(const hs_box2d_t *w)
{
    return w->contacts.contacts;
}

/* A box (centre x, y, half width, height) farther than RAY_MISS_M from the segment from
 * (x0, y0), unit direction (ux, uy), length len, across it or beyond either end: neither
 * cast can hit it. */
static bool off_segment(const double *box, double x0, double y0, double ux, double uy,
                        double len)
{
    const double dx = box[0] - x0, dy = box[1] - y0;
    const double across = std::fabs(uy) * box[2] + std::fabs(ux) * box[3];
    const double along = std::fabs(ux) * box[2] + std::fabs(uy) * box[3];
    const double t = ux * dx + uy * dy;
    return std::fabs(ux * dy - uy * dx) > across + RAY_MISS_M || t < -along - RAY_MISS_M ||
           t > len + along + RAY_MISS_M;
}

/* hs_box2d_walls_crossed(), its fixtures from the radio index or (all) every one. */
static unsigned walls_crossed(const hs_box2d_t *w, double x0, double y0, double x1, double y1,
                              bool all)
{
    double len = std::hypot(x1 - x0, y1 - y0);
    if (len <= 0.0) {
        return 0;
    }
    b2Vec2 a((float)x0, (float)y0), b((float)x1, (float)y1);
    if ((b - a).LengthSquared() <= 0.0f) {
        return 0; // Box2D asserts on a zero-length ray (equal after rounding to float)
    }
    HitCollector &fwd = w->fwd, &rev = w->rev;
    fwd.hits.clear();
    rev.hits.clear();
    b2RayCastInput in_f = {a, b, 1.0f}, in_r = {b, a, 1.0f};
    // The segment's unit direction (ux, uy) and normal (-uy, ux).
    const double ux = (x1 - x0) / len, uy = (y1 - y0) / len;
    if (!all) {
        // Box2D's ray cast without its tree: every radio fixture in a cell the segment
        // (widened by RAY_MARGIN_M) passes, cast at once with the same input b2World::RayCast
        // gives it (maxFraction 1: the collector never clips), so the same hits.
        if (++w->casts == 0u) {
            std::fill(w->seen.begin(), w->seen.end(), 0u);
            w->casts = 1u;
        }
        const double xlo = std::min(x0, x1) - RAY_MARGIN_M, xhi = std::max(x0, x1) + RAY_MARGIN_M;
        const double ylo = std::min(y0, y1) - RAY_MARGIN_M, yhi = std::max(y0, y1) + RAY_MARGIN_M;
        uint32_t i0, j0, i1, j1;
        ray_cells(w, xlo, ylo, xhi, yhi, &i0, &j0, &i1, &j1);
        for (uint32_t i = i0; i <= i1; i++) {
            // The segment's y over this column of cells (all of it for a vertical one).
            double ca = std::max(xlo, w->ox + i * RAY_CELL_M);
            double cb = std::min(xhi, w->ox + (i + 1) * RAY_CELL_M);
            double ya = ylo + RAY_MARGIN_M, yb = yhi - RAY_MARGIN_M;
            if (x1 != x0) {
                double t = (y1 - y0) / (x1 - x0);
                ya = y0 + (std::max(ca, std::min(x0, x1)) - x0) * t;
                yb = y0 + (std::min(cb, std::max(x0, x1)) - x0) * t;
            }
            uint32_t u0, v0, u1, v1;
            ray_cells(w, ca, std::min(ya, yb) - RAY_MARGIN_M, cb, std::max(ya, yb) + RAY_MARGIN_M,
                      &u0, &v0, &u1, &v1);
            for (uint32_t j = v0; j <= v1; j++) {
                const size_t c = (size_t)j * w->rw + i;
                for (uint32_t k = w->first[c]; k < w->first[c + 1u]; k++) {
                    const uint32_t fi = w->fx_of[k];
                    if (w->seen[fi] == w->casts) {
                        continue;
                    }
                    w->seen[fi] = w->casts;
                    if (off_segment(&w->radio_box[4 * fi], x0, y0, ux, uy, len)) {
                        continue;
                    }
                    b2Fixture *f = w->radio_fx[fi];
                    b2RayCastOutput out;
                    if (f->RayCast(&out, in_f, 0)) {
                        fwd.hits.emplace_back(f, out.fraction);
                    }
                    if (f->RayCast(&out, in_r, 0)) {
                        rev.hits.emplace_back(f, out.fraction);
                    }
                }
            }
        }
    } else {
        for (b2Fixture *f : w->radio_fx) {
            b2RayCastOutput out;
            if (f->RayCast(&out, in_f, 0)) {
                fwd.hits.emplace_back(f, out.fraction);
            }
            if (f->RayCast(&out, in_r, 0)) {
                rev.hits.emplace_back(f, out.fraction);
            }
        }
    }
    // Interval of each fixture along the segment, as fractions from a: entry from the
    // forward cast (0 when a is inside), exit from the reverse cast (1 when b is inside).
    // A fixture only one cast reports with the far end outside it was grazed (a corner
    // or an edge touched: the cache points and nodes lie on the map's pixel corners): a
    // crossing of no length there, not an interval to the end that would merge every
    // wall beyond into one (docs/RADIO_MODEL.md, "Walls").
    std::vector<std::pair<double, double>> &iv = w->iv;
    iv.clear();
    for (const auto &h : fwd.hits) {
        double out = -1.0;
        for (const auto &r : rev.hits) {
            if (r.first == h.first) {
                out = 1.0 - r.second;
                break;
            }
        }
        if (out < 0.0) {
            out = h.first->TestPoint(b) ? 1.0 : h.second;
        }
        iv.emplace_back(h.second, out);
    }
    for (const auto &r : rev.hits) {
        bool seen = false;
        for (const auto &h : fwd.hits) {
            if (h.first == r.first) {
                seen = true;
                break;
            }
        }
        if (!seen) {
            iv.emplace_back(r.first->TestPoint(a) ? 0.0 : 1.0 - r.second, 1.0 - r.second);
        }
    }
    if (iv.empty()) {
        return 0;
    }
    std::sort(iv.begin(), iv.end());
    double gap = w->cfg.wall_merge_gap_m / len;
    unsigned n = 1;
    double end = iv[0].second;
    for (size_t i = 1; i < iv.size(); i++) {
        if (iv[i].first > end + gap) {
            n++;
        }
        end = std::max(end, iv[i].second);
    }
    return n;
}

extern "C" unsigned hs_box2d_walls_crossed(const hs_box2d_t *w, double x0, double y0, double x1,
                                           double y1)
{
    return walls_crossed(w, x0, y0, x1, y1, false);
}

extern "C" unsigned hs_box2d_walls_crossed_all(const hs_box2d_t *w, double x0, double y0,
                                                double x1, double y1)
{
    return walls_crossed(w, x0, y0, x1, y1, true);
}

extern "C" bool hs_box2d_disc_blocked(const hs_box2d_t *w, double x, double y)
{
    return disc_blocked_r(w, x, y, w->cfg.robot_radius_m);
}

static bool disc_blocked_r(const hs_box2d_t *w, double x, double y, double r)
{
    double fx0 = (x - r - w->ox) / w->res, fx1 = (x + r - w->ox) / w->res;
    double fy0 = (y - r - w->oy) / w->res, fy1 = (y + r - w->oy) / w->res;
    if (fx0 < 0.0 || fy0 < 0.0 || fx1 >= (double)w->w || fy1 >= (double)w->h) {
        return true;
    }
    for (long cy = (long)fy0; cy <= (long)fy1; cy++) {
        for (long cx = (long)fx0; cx <= (long)fx1; cx++) {
            if (w->cell[(size_t)cy * w->w + (size_t)cx] == LX_CELL_FREE) {
                continue;
            }
            // Nearest point of the cell to the disc centre.
            double cx0 = w->ox + cx * w->res, cy0 = w->oy + cy * w->res;
            double nx = std::min(std::max(x, cx0), cx0 + w->res);
            double ny = std::min(std::max(y, cy0), cy0 + w->res);
            if ((nx - x) * (nx - x) + (ny - y) * (ny - y) < r * r) {
                return true;
            }
        }
    }
    return false;
}
