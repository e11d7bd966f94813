/* test_box2d.c - the Box2D world (hs_box2d.h): rectangle merging, walls stopping the
 * robot, wall counting by ray casts, and one wall costing its attenuation in the radio
 * model. References are computed here from the map cells and plain geometry.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hs_radio.h"
#include "hs_box2d.h"

/// A w x h map at res with free interior and occupied cells from a callback.
static lx_map_t make_map(uint32_t w, uint32_t h, double res, int (*cell)(uint32_t, uint32_t))
{
    lx_map_t m;
    memset(&m, 0, sizeof m);
    m.w = w;
    m.h = h;
    m.res = res;
    m.origin_x = 0.0;
    m.origin_y = 0.0;
    m.occ_th = 0.65;
    m.free_th = 0.196;
    m.cell = malloc((size_t)w * h);
    assert_non_null(m.cell);
    for (uint32_t y = 0; y < h; y++) {
        for (uint32_t x = 0; x < w; x++) {
            m.cell[(size_t)y * w + x] = (uint8_t)cell(x, y);
        }
    }
    return m;
}

/// 10 x 10 m at 0.05 m: outer walls 2 cells thick and one inner wall at x = 5.0..5.1 m
/// from y = 0 up to 8 m (a gap above it).
static int one_wall(uint32_t x, uint32_t y)
{
    if (x < 2 || y < 2 || x >= 198 || y >= 198) {
        return LX_CELL_OCC;
    }
    if (x >= 100 && x < 102 && y < 160) {
        return LX_CELL_OCC;
    }
    return LX_CELL_FREE;
}

/// Three parallel walls at x = 3, 5, 7 m across the whole height, unknown border.
static int three_walls(uint32_t x, uint32_t y)
{
    if (x == 0 || y == 0 || x == 199 || y == 199) {
        return LX_CELL_UNKNOWN;
    }
    if ((x >= 60 && x < 62) || (x >= 100 && x < 102) || (x >= 140 && x < 142)) {
        return LX_CELL_OCC;
    }
    return LX_CELL_FREE;
}

static uint32_t lcg;
static int random_cells(uint32_t x, uint32_t y)
{
    (void)x;
    (void)y;
    lcg = lcg * 1664525u + 1013904223u;
    uint32_t r = (lcg >> 24) % 10u;
    return r < 3 ? LX_CELL_OCC : (r < 4 ? LX_CELL_UNKNOWN : LX_CELL_FREE);
}

/// Every covered cell lies in exactly one rectangle, and nothing else does.
static void test_merge_rects_cover_exactly(void **state)
{
    (void)state;
    lcg = 12345;
    lx_map_t m = make_map(97, 61, 0.05, random_cells);
    for (int kind = 0; kind < 2; kind++) {
        hs_rect_t *r = NULL;
        long n = hs_box2d_merge_rects(&m, (hs_box2d_kind_t)kind, &r);
        assert_true(n > 0);
        uint8_t *cover = calloc((size_t)m.w * m.h, 1);
        for (long i = 0; i < n; i++) {
            for (uint32_t y = r[i].y0; y < r[i].y0 + r[i].h; y++) {
                for (uint32_t x = r[i].x0; x < r[i].x0 + r[i].w; x++) {
                    cover[(size_t)y * m.w + x]++;
                }
            }
        }
        for (size_t i = 0; i < (size_t)m.w * m.h; i++) {
            int want = kind == HS_BOX2D_RADIO ? m.cell[i] == LX_CELL_OCC : m.cell[i] != LX_CELL_FREE;
            assert_int_equal(cover[i], want);
        }
        free(cover);
        free(r);
    }
    free(m.cell);
}

/// An office-like 50 x 50 m map at 5 cm stays at a few rectangles per wall.
static int grid_walls(uint32_t x, uint32_t y)
{
    return (x % 100 < 2 || y % 100 < 2) ? LX_CELL_OCC : LX_CELL_FREE;
}

static void test_merge_rects_cheap(void **state)
{
    (void)state;
    lx_map_t m = make_map(1000, 1000, 0.05, grid_walls);
    hs_rect_t *r = NULL;
    long n = hs_box2d_merge_rects(&m, HS_BOX2D_COLLIDE, &r);
    // 10 horizontal 2-row bands (1 rectangle each) and vertical pieces between them:
    // 10 columns x 10 gaps = 100; every other cell pattern would give 10^5+.
    assert_int_equal(n, 110);
    free(r);
    free(m.cell);
}

/// Driving into a wall: the wall stops the robot at its radius from the wall face.
static void test_walls_stop_the_robot(void **state)
{
    (void)state;
    lx_map_t m = make_map(200, 200, 0.05, one_wall);
    char err[256];
    hs_box2d_t *w = hs_box2d_create(&m, NULL, err, sizeof err);
    assert_non_null(w);
    assert_int_equal(hs_box2d_rect_count(w, HS_BOX2D_RADIO), 5);
    hs_box2d_place_robot(w, 3.0, 4.0, 0.0);
    for (int i = 0; i < 500; i++) { // 10 s at 0.5 m/s: 5 m of wheel travel towards x = 5
        hs_box2d_step(w, 0.5, 0.0, 0.02);
    }
    double x, y, th;
    hs_box2d_robot_pose(w, &x, &y, &th);
    // The wall face is at x = 5.0; the robot's centre stops 0.177 m before it (Box2D
    // keeps a skin of a few mm).
    assert_true(x < 5.0 - 0.177 + 0.02);
    assert_true(x > 5.0 - 0.177 - 0.03);
    assert_true(fabs(y - 4.0) < 0.05);
    assert_true(hs_box2d_robot_touching(w));
    // Free driving: 1 s at 0.5 m/s north from (3, 4) moves 0.5 m.
    hs_box2d_place_robot(w, 3.0, 4.0, M_PI / 2);
    for (int i = 0; i < 50; i++) {
        hs_box2d_step(w, 0.5, 0.0, 0.02);
    }
    hs_box2d_robot_pose(w, &x, &y, &th);
    assert_true(fabs(y - 4.5) < 0.01 && fabs(x - 3.0) < 0.01);
    assert_false(hs_box2d_robot_touching(w));
    // Turning on the spot: 1 rad/s for 1 s.
    for (int i = 0; i < 50; i++) {
        hs_box2d_step(w, 0.0, 1.0, 0.02);
    }
    hs_box2d_robot_pose(w, &x, &y, &th);
    assert_true(fabs(th - (M_PI / 2 + 1.0)) < 0.01);
    hs_box2d_destroy(w);
    free(m.cell);
}

/// Wall contacts from Box2D's contact events: none driving in the open; one when the robot
/// drives into the inner wall (x = 5 m) and keeps pushing; a second after backing off 0.5 m
/// and driving in again; sliding north along the face while pressed against it adds none.
static void test_wall_contacts(void **state)
{
    (void)state;
    lx_map_t m = make_map(200, 200, 0.05, one_wall);
    char err[256];
    hs_box2d_t *w = hs_box2d_create(&m, NULL, err, sizeof err);
    assert_non_null(w);
    hs_box2d_place_robot(w, 3.0, 4.0, M_PI / 2);
    for (int i = 0; i < 100; i++) { // 2 s north in the open
        hs_box2d_step(w, 0.5, 0.0, 0.02);
    }
    assert_int_equal(hs_box2d_wall_contacts(w), 0);
    hs_box2d_place_robot(w, 4.0, 4.0, 0.0);
    for (int i = 0; i < 200; i++) { // east into the wall at x = 5 m, then pushing
        hs_box2d_step(w, 0.5, 0.0, 0.02);
    }
    assert_int_equal(hs_box2d_wall_contacts(w), 1);
    for (int i = 0; i < 50; i++) { // back off 0.5 m
        hs_box2d_step(w, -0.5, 0.0, 0.02);
    }
    assert_false(hs_box2d_robot_touching(w));
    for (int i = 0; i < 100; i++) { // and in again
        hs_box2d_step(w, 0.5, 0.0, 0.02);
    }
    assert_int_equal(hs_box2d_wall_contacts(w), 2);
    // Pressed against the face while sliding north: heading 0.3 rad off the wall's
    // normal keeps it in contact the whole way.
    double x, y, th;
    hs_box2d_robot_pose(w, &x, &y, &th);
    hs_box2d_place_robot(w, x, y, 0.3);
    for (int i = 0; i < 150; i++) {
        hs_box2d_step(w, 0.5, 0.0, 0.02);
        assert_true(hs_box2d_robot_touching(w));
    }
    hs_box2d_robot_pose(w, &x, &y, &th);
    assert_true(y > 4.0 + 0.9 * 3.0 * 0.5 * sin(0.3)); /* frictionless: the along-face part of the motion */
    assert_int_equal(hs_box2d_wall_contacts(w), 2);
    hs_box2d_destroy(w);
    free(m.cell);
}

static void test_walls_crossed(void **state)
{
    (void)state;
    lx_map_t m = make_map(200, 200, 0.05, three_walls);
    char err[256];
    hs_box2d_t *w = hs_box2d_create(&m, NULL, err, sizeof err);
    assert_non_null(w);
    assert_int_equal(hs_box2d_walls_crossed(w, 1.0, 5.0, 9.0, 5.0), 3);
    assert_int_equal(hs_box2d_walls_crossed(w, 9.0, 2.0, 1.0, 8.0), 3);   // either direction, slanted
    assert_int_equal(hs_box2d_walls_crossed(w, 1.0, 5.0, 4.0, 6.0), 1);
    assert_int_equal(hs_box2d_walls_crossed(w, 1.0, 1.0, 2.5, 9.0), 0);   // between walls
    assert_int_equal(hs_box2d_walls_crossed(w, 3.05, 5.0, 4.0, 5.0), 1);  // starts inside a wall
    assert_int_equal(hs_box2d_walls_crossed(w, 1.0, 5.0, 5.05, 5.0), 2);  // ends inside a wall
    assert_int_equal(hs_box2d_walls_crossed(w, 1.0, 5.0, 1.0, 5.0), 0);   // zero length
    // The unknown border is no radio wall.
    assert_int_equal(hs_box2d_walls_crossed(w, 1.0, 0.02, 1.0, 5.0), 0);
    // Collisions: unknown cells stop the robot (it cannot leave the known map).
    assert_true(hs_box2d_disc_blocked(w, 0.1, 5.0));
    assert_true(hs_box2d_disc_blocked(w, 3.0, 5.0));
    assert_false(hs_box2d_disc_blocked(w, 2.0, 5.0));
    hs_box2d_destroy(w);
    free(m.cell);
}

/// Walls on the segment by sampling the map image every 1 mm: runs of occupied cells,
/// runs closer than gap merged (the rule of hs_box2d_walls_crossed, from the cells).
static unsigned image_walls(const lx_map_t *m, double x0, double y0, double x1, double y1, double gap)
{
    const double len = hypot(x1 - x0, y1 - y0);
    const long steps = (long)(len / 0.001) + 1;
    unsigned n = 0;
    double last_end = -1e9; /* distance along the segment where the last run ended */
    bool in = false;
    for (long k = 0; k <= steps; k++) {
        const double t = (double)k / (double)steps, d = t * len;
        const long cx = (long)floor((x0 + t * (x1 - x0) - m->origin_x) / m->res);
        const long cy = (long)floor((y0 + t * (y1 - y0) - m->origin_y) / m->res);
        const bool occ = cx >= 0 && cy >= 0 && cx < (long)m->w && cy < (long)m->h &&
                         m->cell[(size_t)cy * m->w + (size_t)cx] == LX_CELL_OCC;
        if (occ && !in && d > last_end + gap) {
            n++;
        }
        if (!occ && in) {
            last_end = d;
        }
        in = occ;
    }
    return n;
}

/// Segments from pixel corners that graze a wall rectangle's corner, where one cast alone
/// reports that rectangle, and from the points 1 mm round them: each count is the image's
/// or one more (a grazed corner: a crossing of no length), either way along the segment.
/// An interval to the far end merged every wall beyond into one (3ne: 1 for 18-19,
/// Intel lab: 1 for 13-14).
static void test_grazed_corner_keeps_walls_beyond(void **state)
{
    (void)state;
    const struct { const char *map; double x0, y0, x1, y1; unsigned walls; } k[] = {
        {"scenarios/maps/3ne.yaml", -24.65, 0.40, 20.0, -9.0, 18u},
        {"scenarios/maps/intel.yaml", 47.2, 12.5, 3.0, 25.5, 13u},
    };
    for (size_t i = 0; i < sizeof k / sizeof k[0]; i++) {
        lx_map_t m;
        char err[256];
        assert_int_equal(lx_map_load(k[i].map, &m, err, sizeof err), 0);
        hs_box2d_t *w = hs_box2d_create(&m, NULL, err, sizeof err);
        assert_non_null(w);
        assert_int_equal(image_walls(&m, k[i].x0, k[i].y0, k[i].x1, k[i].y1, 0.1), k[i].walls);
        for (int q = 0; q < 9; q++) {
            const double x0 = k[i].x0 + 0.001 * (q % 3 - 1), y0 = k[i].y0 + 0.001 * (q / 3 - 1);
            const unsigned image = image_walls(&m, x0, y0, k[i].x1, k[i].y1, 0.1);
            const unsigned n = hs_box2d_walls_crossed(w, x0, y0, k[i].x1, k[i].y1);
            assert_in_range(n, image, image + 1u);
            assert_int_equal(hs_box2d_walls_crossed(w, k[i].x1, k[i].y1, x0, y0), n);
        }
        hs_box2d_destroy(w);
        lx_map_free(&m);
    }
}

/// One world with the shared merged walls and the walls' pair search skipped, one as
/// Box2D builds it (hs_box2d_create, wall_pairs): the robot driving into, along and away
/// from the Intel lab's cluttered walls for 60 s ends every step at the same pose, bit for
/// bit, with the same contacts; the rectangles and ray counts agree too.
static void test_shared_walls_same_world(void **state)
{
    (void)state;
    lx_map_t m;
    char err[256];
    assert_int_equal(lx_map_load("scenarios/maps/intel.yaml", &m, err, sizeof err), 0);
    hs_box2d_walls_t walls;
    assert_int_equal(hs_box2d_walls_make(&m, &walls), 0);
    hs_box2d_cfg_t ref_cfg = hs_box2d_cfg_default();
    ref_cfg.wall_pairs = true;
    hs_box2d_t *a = hs_box2d_create_walls(&m, NULL, &walls, err, sizeof err);
    hs_box2d_t *b = hs_box2d_create(&m, &ref_cfg, err, sizeof err);
    assert_non_null(a);
    assert_non_null(b);
    for (int k = 0; k < 2; k++) {
        assert_int_equal(hs_box2d_rect_count(a, (hs_box2d_kind_t)k), walls.n[k]);
        assert_int_equal(hs_box2d_rect_count(b, (hs_box2d_kind_t)k), walls.n[k]);
    }
    assert_true(walls.n[HS_BOX2D_RADIO] > 1000);
    hs_box2d_place_robot(a, 26.0, 9.0, 3.14159);
    hs_box2d_place_robot(b, 26.0, 9.0, 3.14159);
    int touching = 0;
    for (int i = 0; i < 3000; i++) { // 60 s: forward, turning now and then, backing off
        double v = (i / 400) % 3 == 2 ? -0.3 : 0.6, om = (i / 150) % 4 == 1 ? 0.9 : -0.2;
        hs_box2d_step(a, v, om, 0.02);
        hs_box2d_step(b, v, om, 0.02);
        double xa, ya, ta, xb, yb, tb;
        hs_box2d_robot_pose(a, &xa, &ya, &ta);
        hs_box2d_robot_pose(b, &xb, &yb, &tb);
        assert_memory_equal(&xa, &xb, sizeof xa);
        assert_memory_equal(&ya, &yb, sizeof ya);
        assert_memory_equal(&ta, &tb, sizeof ta);
        assert_int_equal(hs_box2d_robot_touching(a), hs_box2d_robot_touching(b));
        touching += hs_box2d_robot_touching(a);
    }
    assert_int_equal(hs_box2d_wall_contacts(a), hs_box2d_wall_contacts(b));
    assert_true(hs_box2d_wall_contacts(a) >= 2);
    assert_true(touching > 100);
    assert_int_equal(hs_box2d_walls_crossed(a, 1.0, 1.0, 30.0, 25.0),
                     hs_box2d_walls_crossed(b, 1.0, 1.0, 30.0, 25.0));
    hs_box2d_destroy(a);
    hs_box2d_destroy(b);
    hs_box2d_walls_free(&walls);
    lx_map_free(&m);
}

/// xorshift64: the test's own segments, the same on every run.
static double uniform(uint64_t *s, double lo, double hi)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return lo + (hi - lo) * (double)(*s >> 11) / 9007199254740992.0;
}

/// The radio-fixture index answers as casting every radio fixture (both ways) on
/// the shipped SLAM map (thousands of small walls) for random segments, segments along
/// cell edges and through corners, vertical and horizontal ones, and ends off the map.
static void test_walls_crossed_index_matches_all(void **state)
{
    (void)state;
    lx_map_t m;
    char err[256];
    assert_int_equal(lx_map_load("scenarios/maps/intel.yaml", &m, err, sizeof err), 0);
    hs_box2d_t *w = hs_box2d_create(&m, NULL, err, sizeof err);
    assert_non_null(w);
    const double x1 = m.origin_x + m.w * m.res, y1 = m.origin_y + m.h * m.res;
    uint64_t s = 0x9E3779B97F4A7C15u;
    unsigned walls = 0, differ = 0;
    for (int k = 0; k < 3000; k++) {
        double a = uniform(&s, m.origin_x - 1.0, x1 + 1.0), b = uniform(&s, m.origin_y - 1.0, y1 + 1.0);
        double c = uniform(&s, m.origin_x - 1.0, x1 + 1.0), d = uniform(&s, m.origin_y - 1.0, y1 + 1.0);
        if (k % 4 == 1) { // on cell edges and corners
            a = m.origin_x + floor((a - m.origin_x) / m.res) * m.res;
            b = m.origin_y + floor((b - m.origin_y) / m.res) * m.res;
            c = m.origin_x + floor((c - m.origin_x) / m.res) * m.res;
            d = m.origin_y + floor((d - m.origin_y) / m.res) * m.res;
        } else if (k % 4 == 2) {
            c = a; // vertical
        } else if (k % 4 == 3) {
            d = b; // horizontal
        }
        if (k % 8 == 5) { // short: ends beside the boxes the index holds
            c = a + uniform(&s, -0.7, 0.7);
            d = b + uniform(&s, -0.7, 0.7);
        }
        unsigned n = hs_box2d_walls_crossed(w, a, b, c, d);
        walls += n;
        differ += n != hs_box2d_walls_crossed_all(w, a, b, c, d) ? 1u : 0u;
    }
    assert_int_equal(differ, 0);
    assert_true(walls > 3000u * 4u); // the segments do cross the lab's walls
    hs_box2d_destroy(w);
    lx_map_free(&m);
}

/// Drive w's robot from the Intel lab's start for n steps (forward, turning now and then,
/// backing off: it meets walls), the poses into xs (3 doubles a step).
static void drive(hs_box2d_t *w, int n, double *xs)
{
    hs_box2d_place_robot(w, 26.0, 9.0, 3.14159);
    for (int i = 0; i < n; i++) {
        double v = (i / 400) % 3 == 2 ? -0.3 : 0.6, om = (i / 150) % 4 == 1 ? 0.9 : -0.2;
        hs_box2d_step(w, v, om, 0.02);
        hs_box2d_robot_pose(w, &xs[3 * i], &xs[3 * i + 1], &xs[3 * i + 2]);
    }
}

/// A reset world drives as a new one, bit for bit (poses, contacts), after runs that
/// touched walls and after a kidnap; one keeping wall pairs is not reset.
static void test_reset_same_as_new(void **state)
{
    (void)state;
    lx_map_t m;
    char err[256];
    assert_int_equal(lx_map_load("scenarios/maps/intel.yaml", &m, err, sizeof err), 0);
    enum { N = 3000 };
    double *ref = malloc(sizeof(double) * 3 * N), *got = malloc(sizeof(double) * 3 * N);
    assert_non_null(ref);
    assert_non_null(got);
    hs_box2d_t *fresh = hs_box2d_create(&m, NULL, err, sizeof err);
    assert_non_null(fresh);
    drive(fresh, N, ref);
    const long contacts = hs_box2d_wall_contacts(fresh);
    assert_true(contacts >= 2); // the drive does meet walls
    hs_box2d_destroy(fresh);
    hs_box2d_t *w = hs_box2d_create(&m, NULL, err, sizeof err);
    assert_non_null(w);
    for (int run = 0; run < 3; run++) {
        if (run == 2) {
            hs_box2d_place_robot(w, 10.0, 20.0, 1.0); // kidnapped mid-run, then reset
            hs_box2d_step(w, 0.5, 0.0, 0.02);
        }
        if (run > 0) {
            assert_int_equal(hs_box2d_reset(w), 0);
            assert_int_equal(hs_box2d_wall_contacts(w), 0);
        }
        drive(w, N, got);
        assert_memory_equal(got, ref, sizeof(double) * 3 * N);
        assert_int_equal(hs_box2d_wall_contacts(w), contacts);
    }
    hs_box2d_destroy(w);
    hs_box2d_cfg_t pairs = hs_box2d_cfg_default();
    pairs.wall_pairs = true;
    w = hs_box2d_create(&m, &pairs, err, sizeof err);
    assert_non_null(w);
    assert_int_equal(hs_box2d_reset(w), -1);
    hs_box2d_destroy(w);
    free(ref);
    free(got);
    lx_map_free(&m);
}

static unsigned walls_cb(void *ctx, double x0, double y0, double x1, double y1)
{
    return hs_box2d_walls_crossed(ctx, x0, y0, x1, y1);
}

/// One wall between receiver and source costs exactly its attenuation.
static void test_one_wall_costs_its_attenuation(void **state)
{
    (void)state;
    lx_map_t m = make_map(200, 200, 0.05, one_wall);
    char err[256];
    hs_box2d_t *w = hs_box2d_create(&m, NULL, err, sizeof err);
    assert_non_null(w);
    hs_radio_cfg_t c = hs_radio_cfg_default();
    c.shadowing = c.fading = c.noise = c.quantise = c.clip = c.loss = false;
    hs_radio_src_t src = {7.0, 4.0, 20.0};
    hs_radio_t *r = hs_radio_create(&c, &src, 1, 0, 0, 10, 10, 1, walls_cb, w, err, sizeof err);
    assert_non_null(r);
    // Receivers 4 m from the source: (3, 4) behind the wall at x = 5, (7, 8) in the open
    // (straight above the source, nothing in between).
    double behind = hs_radio_mean_dbm(r, 0, 3.0, 4.0);
    double open = hs_radio_mean_dbm(r, 0, 7.0, 8.0);
    assert_int_equal(hs_radio_walls(r, 0, 3.0, 4.0), 1);
    assert_int_equal(hs_radio_walls(r, 0, 7.0, 8.0), 0);
    assert_true(fabs((open - behind) - 5.0) < 1e-9);
    // And the absolute value: 20 - (20 log10 2400 - 28) - 30 log10 4 - 5.
    double ref = 20.0 - (20.0 * log10(2400.0) - 28.0) - 30.0 * log10(4.0) - 5.0;
    assert_true(fabs(behind - ref) < 1e-9);
    // On the source's side of the wall the line is clear.
    assert_int_equal(hs_radio_walls(r, 0, 9.0, 9.0), 0);
    hs_radio_destroy(r);
    hs_box2d_destroy(w);
    free(m.cell);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_merge_rects_cover_exactly),
        cmocka_unit_test(test_merge_rects_cheap),
        cmocka_unit_test(test_walls_stop_the_robot),
        cmocka_unit_test(test_wall_contacts),
        cmocka_unit_test(test_walls_crossed),
        cmocka_unit_test(test_grazed_corner_keeps_walls_beyond),
        cmocka_unit_test(test_walls_crossed_index_matches_all),
        cmocka_unit_test(test_shared_walls_same_world),
        cmocka_unit_test(test_reset_same_as_new),
        cmocka_unit_test(test_one_wall_costs_its_attenuation),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
