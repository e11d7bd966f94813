/* test_lx_map.c - the ROS map_server loader and the conversion to the core's grids.
 *
 * Independent references: the cell counts of the real maps are the table in
 * /work/shared/data/README.md (counted there with a separate PGM reader) and, for the
 * floors added since, numpy's (scenarios/maps/README.md); the copies in scenarios/maps
 * are read (RFS_MAPS_DIR overrides); orientation
 * and thresholds are checked on a 4 x 3 image whose pixel values are written here; the
 * conservative resampling is recomputed here by 2 x 2 blocks on the Willow Garage map.
 * Bad input: every fixture in tests/data/maps_bad gives -1 and one line naming the file;
 * a document one node over LX_YAML_MAX_NODES is written here.
 */
#include "rfs_test.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "lx_map.h"
#include "lx_yaml.h"

#define BAD "tests/data/maps_bad/"

static const char *maps_dir(void)
{
    const char *d = getenv("RFS_MAPS_DIR");
    return d != NULL ? d : "scenarios/maps";
}

static void load_real(const char *name, lx_map_t *m)
{
    char path[512];
    char err[512] = "";
    snprintf(path, sizeof(path), "%s/%s", maps_dir(), name);
    int rc = lx_map_load(path, m, err, sizeof(err));
    if (rc != 0) {
        print_error("%s\n", err);
    }
    assert_int_equal(rc, 0);
}

/* The READMEs' tables: size, resolution, origin, and occupied / free / unknown counts
 * (the last three by numpy with map_server's trinary rule). */
static void test_real_maps_counts(void **state)
{
    (void)state;
    struct {
        const char *yaml;
        uint32_t w, h;
        double res, ox, oy;
        uint32_t occ, fre, unk;
    } t[8] = {
        {"willow-full-0.05.yaml", 1165, 945, 0.05, 0.0, 0.0, 13459, 549308, 538158},
        {"3ne.yaml", 1857, 573, 0.05, -60.45, -23.4, 34019, 456354, 573688},
        {"intel.yaml", 579, 581, 0.1, 0.0, 0.0, 29942, 192948, 113509},
        {"gdc2.yaml", 1800, 1400, 0.05, -53.95, -29.15, 29525, 472275, 2018200},
        {"gdc4.yaml", 1857, 1255, 0.05, -60.45, -23.4, 72493, 543112, 1714930},
        {"house.yaml", 500, 500, 0.05, -12.5, -12.5, 3442, 63021, 183537},
        {"bookstore.yaml", 384, 384, 0.05, -10.0, -10.0, 4954, 61884, 80618},
        {"warehouse.yaml", 286, 423, 0.05, -7.0, -10.5, 3673, 93698, 23607}, /* an RGB PNG */
    };
    for (int k = 0; k < 8; k++) {
        lx_map_t m;
        load_real(t[k].yaml, &m);
        assert_int_equal(m.w, t[k].w);
        assert_int_equal(m.h, t[k].h);
        assert_true(m.res == t[k].res);
        assert_true(m.origin_x == t[k].ox && m.origin_y == t[k].oy);
        uint32_t f;
        uint32_t o;
        uint32_t u;
        lx_map_count(&m, &f, &o, &u);
        assert_int_equal(o, t[k].occ);
        assert_int_equal(f, t[k].fre);
        assert_int_equal(u, t[k].unk);
        lx_map_free(&m);
    }
}

/* lx_map_cell_at on 3ne (origin (-60.45, -23.4), 0.05 m, 1857 x 573): cells worked out by
 * hand from the YAML's numbers; points off the map and NaN are refused. */
static void test_cell_at(void **state)
{
    (void)state;
    lx_map_t m;
    load_real("3ne.yaml", &m);
    static const struct {
        double x, y;
        bool on;
        uint32_t cx, cy;
    } t[] = {
        {-60.44, -23.39, true, 0, 0},       {-59.925, -23.04, true, 10, 7},
        {32.375, 5.225, true, 1856, 572},   {0.01, 0.01, true, 1209, 468},
        {-60.46, -23.0, false, 0, 0},       {-60.0, -23.41, false, 0, 0},
        {32.5, 0.0, false, 0, 0},           {0.0, 5.3, false, 0, 0},
        {NAN, 0.0, false, 0, 0},            {0.0, NAN, false, 0, 0},
    };
    for (size_t k = 0; k < sizeof t / sizeof t[0]; k++) {
        uint32_t cx = UINT32_MAX, cy = UINT32_MAX;
        assert_int_equal(lx_map_cell_at(&m, t[k].x, t[k].y, &cx, &cy), t[k].on);
        if (t[k].on) {
            assert_int_equal(cx, t[k].cx);
            assert_int_equal(cy, t[k].cy);
        }
    }
    lx_map_free(&m);
}

/* Row 0 of the PGM is the top of the map; thresholds; negate; P2 and P5 agree. */
static void test_orientation_thresholds_negate(void **state)
{
    (void)state;
    /* ok.pgm, rows top to bottom: [254 254 0 205] [254 254 254 254] [0 0 205 254].
     * p = (255 - v) / 255: 254 -> 0.004 free, 0 -> 1.0 occupied, 205 -> 0.196 (not
     * < 0.196, not > 0.65): unknown. */
    lx_map_t m;
    char err[512] = "";
    assert_int_equal(lx_map_load(BAD "ok.yaml", &m, err, sizeof(err)), 0);
    assert_int_equal(m.w, 4);
    assert_int_equal(m.h, 3);
    const uint8_t want[3][4] = {
        /* bottom row (PGM row 2) first */
        {LX_CELL_OCC, LX_CELL_OCC, LX_CELL_UNKNOWN, LX_CELL_FREE},
        {LX_CELL_FREE, LX_CELL_FREE, LX_CELL_FREE, LX_CELL_FREE},
        {LX_CELL_FREE, LX_CELL_FREE, LX_CELL_OCC, LX_CELL_UNKNOWN},
    };
    for (int y = 0; y < 3; y++) {
        for (int x = 0; x < 4; x++) {
            assert_int_equal(m.cell[y * 4 + x], want[y][x]);
        }
    }
    lx_map_free(&m);

    /* The same image as P2 with negate 1 in a temporary directory: p = v / 255, so
     * 254 -> occupied, 0 -> free, 205 (0.804) -> occupied. */
    char dir[] = "/tmp/rfs_hs_map_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char yp[256];
    char ip[256];
    snprintf(yp, sizeof(yp), "%s/n.yaml", dir);
    snprintf(ip, sizeof(ip), "%s/n.pgm", dir);
    FILE *f = fopen(ip, "w");
    assert_non_null(f);
    fputs("P2\n4 3\n255\n254 254 0 205\n254 254 254 254\n0 0 205 254\n", f);
    fclose(f);
    f = fopen(yp, "w");
    assert_non_null(f);
    fputs("image: n.pgm\nresolution: 0.5\norigin: [1.5, -2, 0]\nnegate: 1\n"
          "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n", f);
    fclose(f);
    assert_int_equal(lx_map_load(yp, &m, err, sizeof(err)), 0);
    assert_true(m.origin_x == 1.5 && m.origin_y == -2.0 && m.res == 0.5 && m.negate == 1);
    for (int y = 0; y < 3; y++) {
        for (int x = 0; x < 4; x++) {
            uint8_t w = want[y][x];
            uint8_t neg = w == LX_CELL_FREE ? LX_CELL_OCC : LX_CELL_FREE;
            if (w == LX_CELL_UNKNOWN) {
                neg = LX_CELL_OCC;
            }
            assert_int_equal(m.cell[y * 4 + x], neg);
        }
    }
    lx_map_free(&m);
    remove(yp);
    remove(ip);
    rmdir(dir);
}

/* Each bad fixture: -1, one line "file: reason" naming the right file and reason. */
static void test_bad_input(void **state)
{
    (void)state;
    struct {
        const char *yaml;
        const char *file; /* the file the message must name */
        const char *reason;
    } t[] = {
        {BAD "missing.yaml", BAD "missing.yaml", "cannot open"},
        {BAD "malformed.yaml", BAD "malformed.yaml", "malformed YAML"},
        {BAD "truncated.yaml", BAD "truncated.yaml", "malformed YAML at line 4"},
        {BAD "notmapping.yaml", BAD "notmapping.yaml", "mapping"},
        {BAD "image_not_found.yaml", BAD "nothere.pgm", "cannot open"},
        {BAD "image_truncated.yaml", BAD "truncated.pgm", "truncated"},
        {BAD "image_oversize.yaml", BAD "oversize.pgm", "after the 4 x 3 raster"},
        {BAD "image_badheader.yaml", BAD "badheader.pgm", "header"},
        {BAD "image_notpgm.yaml", BAD "notpgm.pgm", "not a PGM"},
        {BAD "image_badpixel.yaml", BAD "badpixel.pgm", "bad pixel value"},
        {BAD "res_zero.yaml", BAD "res_zero.yaml", "resolution: must be > 0"},
        {BAD "res_negative.yaml", BAD "res_negative.yaml", "resolution: must be > 0"},
        {BAD "res_text.yaml", BAD "res_text.yaml", "resolution: a number expected"},
        /* outside 1 mm .. 10 m: the resampling would loop over billions of fine cells */
        {BAD "res_tiny.yaml", BAD "res_tiny.yaml", "resolution: 1e-10 m out of range (0.001 .. 10 m per pixel)"},
        {BAD "res_denormal.yaml", BAD "res_denormal.yaml", "resolution: 1e-300 m out of range"},
        {BAD "res_huge.yaml", BAD "res_huge.yaml", "resolution: 11 m out of range"},
        {BAD "thresh_order.yaml", BAD "thresh_order.yaml", "out of order"},
        {BAD "thresh_range.yaml", BAD "thresh_range.yaml", "[0, 1]"},
        {BAD "mode_bad.yaml", BAD "mode_bad.yaml", "mode: 'Scale' unknown (trinary, scale or raw)"},
        {BAD "negate_bad.yaml", BAD "negate_bad.yaml", "negate: 0 or 1 expected"},
        {BAD "yaw.yaml", BAD "yaw.yaml", "yaw 0.5 unsupported"},
        {BAD "origin_short.yaml", BAD "origin_short.yaml", "origin: a list of three numbers"},
        {BAD "missing_free.yaml", BAD "missing_free.yaml", "missing key 'free_thresh'"},
        /* line breaks in the image name (found by fuzz_map): still one line, shown as '?' */
        {BAD "image_newline.yaml", BAD "nothere??folded.pgm", "cannot open"},
    };
    for (size_t k = 0; k < sizeof(t) / sizeof(t[0]); k++) {
        lx_map_t m;
        char err[512] = "";
        int rc = lx_map_load(t[k].yaml, &m, err, sizeof(err));
        print_message("%s -> %s\n", t[k].yaml, err);
        assert_int_equal(rc, -1);
        assert_null(m.cell);
        char prefix[300];
        snprintf(prefix, sizeof(prefix), "%s: ", t[k].file);
        assert_true(strncmp(err, prefix, strlen(prefix)) == 0);
        assert_non_null(strstr(err, t[k].reason));
        assert_null(strchr(err, '\n'));
    }
}

/* ok.yaml's 16 nodes (with the image named by its absolute path) and a list of `items`
 * scalars under an ignored key (2 nodes more): 18 + items nodes in all. */
static void write_padded(const char *yaml, unsigned items)
{
    char img[PATH_MAX];
    assert_non_null(realpath(BAD "ok.pgm", img));
    FILE *f = fopen(yaml, "w");
    assert_non_null(f);
    fprintf(f, "image: %s\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
               "occupied_thresh: 0.65\nfree_thresh: 0.196\npad: [", img);
    for (unsigned k = 0; k < items; k++) {
        fputs(k ? ",0" : "0", f);
    }
    fputs("]\n", f);
    assert_int_equal(fclose(f), 0);
}

/* The document bound (lx_yaml.h): LX_YAML_MAX_NODES nodes load, one more is refused
 * with one line naming the file, and nothing is left allocated. */
static void test_yaml_node_bound(void **state)
{
    (void)state;
    char dir[] = "/tmp/rfs_lx_map_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char yp[256];
    snprintf(yp, sizeof(yp), "%s/big.yaml", dir);
    lx_map_t m;
    char err[512] = "";

    write_padded(yp, LX_YAML_MAX_NODES - 18u);
    assert_int_equal(lx_map_load(yp, &m, err, sizeof(err)), 0);
    assert_int_equal(m.w, 4);
    assert_int_equal(m.h, 3);
    lx_map_free(&m);

    write_padded(yp, LX_YAML_MAX_NODES - 17u);
    assert_int_equal(lx_map_load(yp, &m, err, sizeof(err)), -1);
    print_message("%s\n", err);
    char want[400];
    snprintf(want, sizeof(want), "%s: more than %u YAML nodes", yp, LX_YAML_MAX_NODES);
    assert_string_equal(err, want);
    assert_null(m.cell);
    remove(yp);
    rmdir(dir);
}

/* Intel at its own 0.1 m: one fine cell per core cell, so the core's free and wall bits
 * count exactly the README's free and occupied cells. */
static void test_core_same_resolution(void **state)
{
    (void)state;
    lx_map_t m;
    load_real("intel.yaml", &m);
    lx_core_map_t c;
    char err[512] = "";
    assert_int_equal(lx_map_to_core(&m, 0.1, NULL, &c, err, sizeof(err)), 0);
    assert_int_equal(c.map.w, 579);
    assert_int_equal(c.map.h, 581);
    uint32_t nf = 0;
    uint32_t nw = 0;
    for (uint16_t y = 0; y < c.map.h; y++) {
        for (uint16_t x = 0; x < c.map.w; x++) {
            nf += rfs_map_bit(c.free_bits, c.map.stride, x, y);
            nw += rfs_map_bit(c.wall_bits, c.map.stride, x, y);
        }
    }
    assert_int_equal(nf, 192948);
    assert_int_equal(nw, 29942);
    lx_core_map_free(&c);
    lx_map_free(&m);
}

/* Willow at 0.05 m to 0.1 m: each core cell is a 2 x 2 block (the last column half off
 * the image, which is not free). Free = all four free; wall = any occupied. */
static void test_core_conservative(void **state)
{
    (void)state;
    lx_map_t m;
    load_real("willow-full-0.05.yaml", &m);
    lx_core_map_t c;
    char err[512] = "";
    assert_int_equal(lx_map_to_core(&m, 0.1, NULL, &c, err, sizeof(err)), 0);
    assert_int_equal(c.map.w, (1165 + 1) / 2);
    assert_int_equal(c.map.h, (945 + 1) / 2);
    uint32_t mism = 0;
    uint32_t nfree = 0;
    for (uint32_t y = 0; y < c.map.h; y++) {
        for (uint32_t x = 0; x < c.map.w; x++) {
            int all_free = 1;
            int any_occ = 0;
            for (uint32_t dy = 0; dy < 2; dy++) {
                for (uint32_t dx = 0; dx < 2; dx++) {
                    uint32_t fx = 2 * x + dx;
                    uint32_t fy = 2 * y + dy;
                    if (fx >= m.w || fy >= m.h) {
                        all_free = 0;
                        continue;
                    }
                    uint8_t s = m.cell[fy * m.w + fx];
                    all_free &= s == LX_CELL_FREE;
                    any_occ |= s == LX_CELL_OCC;
                }
            }
            nfree += (uint32_t)all_free;
            mism += rfs_map_bit(c.free_bits, c.map.stride, (uint16_t)x, (uint16_t)y) != all_free;
            mism += rfs_map_bit(c.wall_bits, c.map.stride, (uint16_t)x, (uint16_t)y) != any_occ;
        }
    }
    assert_int_equal(mism, 0);
    assert_true(nfree > 100000);
    /* The core map's origin and resolution are the Q16 roundings of the yaml's. */
    assert_int_equal(c.map.res, 6554);
    assert_int_equal(c.map.origin_x, 0);
    lx_core_map_free(&c);
    lx_map_free(&m);
}

/* Bad core conversions: resolution <= 0; a grid above 65535 cells. */
static void test_core_rejects(void **state)
{
    (void)state;
    lx_map_t m;
    load_real("intel.yaml", &m);
    lx_core_map_t c;
    char err[512] = "";
    assert_int_equal(lx_map_to_core(&m, 0.0, NULL, &c, err, sizeof(err)), -1);
    assert_non_null(strstr(err, "map: core resolution"));
    assert_int_equal(lx_map_to_core(&m, 0.0005, NULL, &c, err, sizeof(err)), -1);
    assert_non_null(strstr(err, "does not fit"));
    assert_null(c.free_bits);
    /* A map built in memory with a resolution no YAML may give: refused, not resampled. */
    m.res = 1e-10;
    assert_int_equal(lx_map_to_core(&m, 0.1, NULL, &c, err, sizeof(err)), -1);
    assert_string_equal(err, "map: resolution 1e-10 m out of range (0.001 .. 10 m per pixel)");
    assert_null(c.free_bits);
    lx_map_free(&m);
}

/* `levels` nested flow sequences as the value of "image:" in dir/deep.yaml. */
static void write_deep(const char *path, long levels)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("image: ", f);
    for (long i = 0; i < levels; i++) {
        fputc('[', f);
    }
    for (long i = 0; i < levels; i++) {
        fputc(']', f);
    }
    fputs("\nresolution: 0.05\n", f);
    assert_int_equal(fclose(f), 0);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Nesting deeper than LX_YAML_MAX_DEPTH: refused at once with one line, through the map
 * loader (lx_yaml_load_string) and from a stream (lx_yaml_load_file, the scenario's);
 * libyaml took 3.8 s to compose 40,000 levels, over a minute for 100,000. 64 levels pass
 * the depth check (and fail later as a map, on the image). */
static void test_yaml_depth(void **state)
{
    (void)state;
    char dir[] = "/tmp/rfs_lx_yaml_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char yp[256];
    char want[512];
    char err[512] = "";
    snprintf(yp, sizeof(yp), "%s/deep.yaml", dir);
    snprintf(want, sizeof(want), "%s: malformed YAML at line 1: nesting deeper than 64 levels", yp);
    const long levels[] = {40000, 100000, 65};
    for (size_t k = 0; k < 3; k++) {
        write_deep(yp, levels[k]);
        lx_map_t m;
        double t0 = now_s();
        assert_int_equal(lx_map_load(yp, &m, err, sizeof(err)), -1);
        assert_string_equal(err, want);
        FILE *f = fopen(yp, "rb");
        assert_non_null(f);
        lx_yaml_doc_t doc;
        lx_yaml_error_t ye;
        assert_int_equal(lx_yaml_load_file(f, &doc, &ye), LX_YAML_SYNTAX);
        fclose(f);
        lx_yaml_free(&doc);
        assert_int_equal(ye.line, 1);
        assert_string_equal(ye.problem, "nesting deeper than 64 levels");
        assert_true(now_s() - t0 < 0.5);
    }
    write_deep(yp, 63); /* with the root mapping: 64 levels */
    lx_map_t m;
    assert_int_equal(lx_map_load(yp, &m, err, sizeof(err)), -1);
    snprintf(want, sizeof(want), "%s: image: a file name expected", yp);
    assert_string_equal(err, want);
    remove(yp);
    rmdir(dir);
}

/* lx_yaml_read: a stream of max bytes is read whole, one of max + 1 or more gives max + 1
 * (the caller's "larger than" verdict); the bytes arrive unchanged across the buffer's
 * growth (4 KB, doubled), including at the growth boundaries. */
static void test_yaml_read_bounds(void **state)
{
    (void)state;
    enum { MAX = 20000 };
    static uint8_t src[MAX + 100];
    for (size_t i = 0; i < sizeof(src); i++) {
        src[i] = (uint8_t)(i * 131u + 7u);
    }
    const size_t sizes[] = {0, 1, 4095, 4096, 4097, 8192, MAX - 1, MAX, MAX + 1, MAX + 100};
    for (size_t k = 0; k < sizeof(sizes) / sizeof(sizes[0]); k++) {
        FILE *f = sizes[k] > 0 ? fmemopen(src, sizes[k], "rb") : fopen("/dev/null", "rb");
        assert_non_null(f);
        uint8_t *b = NULL;
        size_t n = 99;
        assert_int_equal(lx_yaml_read(f, MAX, &b, &n), 0);
        fclose(f);
        const size_t want = sizes[k] > MAX ? MAX + 1 : sizes[k];
        assert_int_equal(n, want);
        assert_non_null(b);
        assert_memory_equal(b, src, want);
        free(b);
    }
}

static long max_rss_kb(void)
{
    struct rusage ru;
    assert_int_equal(getrusage(RUSAGE_SELF, &ru), 0);
    return ru.ru_maxrss;
}

/* Writes a map YAML naming `image` into dir/m.yaml; returns its path in yp. */
static void write_yaml(const char *dir, const char *image, char *yp, size_t n)
{
    snprintf(yp, n, "%s/m.yaml", dir);
    FILE *f = fopen(yp, "w");
    assert_non_null(f);
    fprintf(f, "image: %s\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.196\n", image);
    assert_int_equal(fclose(f), 0);
}

/* An endless image (/dev/zero) and a 3 GB sparse PGM whose header says 100 x 80: only
 * what the header declares is read, then one byte proves data after it; the process grows
 * by far less than 100 MB (reading either whole took gigabytes). */
static void test_image_bounded(void **state)
{
    (void)state;
    char dir[] = "/tmp/rfs_lx_map_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char yp[256];
    char ip[256];
    char err[512] = "";
    lx_map_t m;
    long rss0 = max_rss_kb();

    write_yaml(dir, "/dev/zero", yp, sizeof(yp));
    assert_int_equal(lx_map_load(yp, &m, err, sizeof(err)), -1);
    assert_string_equal(err, "/dev/zero: not a PGM or PNG image (magic P5, P2 or the PNG signature expected)");

    snprintf(ip, sizeof(ip), "%s/sparse.pgm", dir);
    FILE *f = fopen(ip, "w");
    assert_non_null(f);
    fputs("P5\n100 80\n255\n", f);
    assert_int_equal(fclose(f), 0);
    assert_int_equal(truncate(ip, 3LL << 30), 0);
    write_yaml(dir, "sparse.pgm", yp, sizeof(yp));
    assert_int_equal(lx_map_load(yp, &m, err, sizeof(err)), -1);
    char want[512];
    /* header 14 bytes + 8000 raster bytes: the first byte after them is at offset 8014 */
    snprintf(want, sizeof(want), "%s: data after the 100 x 80 raster the header declares (at byte 8014)", ip);
    assert_string_equal(err, want);
    assert_null(m.cell);

    /* The YAML itself: /dev/zero as the map file is cut off at 1 MB. */
    assert_int_equal(lx_map_load("/dev/zero", &m, err, sizeof(err)), -1);
    assert_string_equal(err, "/dev/zero: larger than 1048576 bytes (a map_server YAML is a few lines)");

    assert_true(max_rss_kb() - rss0 < 100 * 1024);
    remove(ip);
    remove(yp);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_real_maps_counts),
        cmocka_unit_test(test_orientation_thresholds_negate),
        cmocka_unit_test(test_cell_at),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_yaml_node_bound),
        cmocka_unit_test(test_core_same_resolution),
        cmocka_unit_test(test_core_conservative),
        cmocka_unit_test(test_core_rejects),
        cmocka_unit_test(test_image_bounded),
        cmocka_unit_test(test_yaml_depth),
        cmocka_unit_test(test_yaml_read_bounds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
