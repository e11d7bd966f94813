/* fuzz_png - libFuzzer target for the PNG path of the map loader (firmware/port/linux/
 * lx_png.h through lx_map.h).
 *
 * Input: one reading byte b (mode b % 3: trinary, scale, raw; negate b / 3 % 2), then the
 * PNG file's bytes. Before it is written, every chunk's CRC is recomputed where the chunk
 * fits in the input, so mutations reach the decoder instead of stopping at the CRC check.
 * The file is m.png in a private tmpfs directory, named by a fixed YAML.
 *
 * Beyond ASan/UBSan it checks lx_map.h's promises: failure gives one non-empty error
 * line and leaves nothing allocated; success gives 1..2^26 pixels, values in -1..100
 * (lx_map_load_values), cells equal to lx_map_cell_of of those values (lx_map_load), and
 * a crop to the known area that holds the same cells.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_tmp.h"
#include "lx_map.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static uint32_t crc32_of(const uint8_t *p, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++) {
            c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
        }
    }
    return ~c;
}

/* Recompute the CRC of every whole chunk after the 8-byte signature. */
static void fix_crcs(uint8_t *p, size_t n)
{
    size_t at = 8;
    while (at + 12 <= n) {
        uint32_t len = (uint32_t)p[at] << 24 | (uint32_t)p[at + 1] << 16 | (uint32_t)p[at + 2] << 8 | p[at + 3];
        if (len > n - at - 12) {
            break;
        }
        uint32_t c = crc32_of(p + at + 4, (size_t)len + 4);
        uint8_t *q = p + at + 8 + len;
        q[0] = (uint8_t)(c >> 24);
        q[1] = (uint8_t)(c >> 16);
        q[2] = (uint8_t)(c >> 8);
        q[3] = (uint8_t)c;
        at += 12 + (size_t)len;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) {
        return 0;
    }
    static const char *const modes[3] = {"trinary", "scale", "raw"};
    char yaml[256];
    int ylen = snprintf(yaml, sizeof yaml, "image: m.png\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: %d\n"
                        "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: %s\n", data[0] / 3 % 2, modes[data[0] % 3]);
    uint8_t *png = malloc(size);
    if (png == NULL) {
        return 0;
    }
    memcpy(png, data + 1, size - 1);
    fix_crcs(png, size - 1);
    const char *ypath = fuzz_tmp_write(0, "m.yaml", yaml, (size_t)ylen);
    (void)fuzz_tmp_write(1, "m.png", png, size - 1);
    free(png);

    lx_map_t v;
    lx_map_t c;
    char err[512] = "";
    int rv = lx_map_load_values(ypath, &v, err, sizeof err);
    if (rv != 0) {
        fuzz_check_err_line(err);
        if (v.value != NULL || v.cell != NULL || v.image_path != NULL) { abort(); }
    }
    int rc = lx_map_load(ypath, &c, err, sizeof err);
    if (rc != 0) {
        fuzz_check_err_line(err);
        if (c.cell != NULL || c.image_path != NULL) { abort(); }
    }
    if ((rv == 0) != (rc == 0)) { abort(); } /* the two loads read the same file alike */
    if (rc == 0) {
        const uint64_t n = (uint64_t)c.w * c.h;
        if (n == 0 || n > (1ull << 26) || v.w != c.w || v.h != c.h || v.value == NULL || c.cell == NULL) { abort(); }
        for (uint64_t i = 0; i < n; i++) {
            if (v.value[i] < -1 || v.value[i] > 100 || c.cell[i] != lx_map_cell_of(v.value[i])) { abort(); }
        }
        uint32_t x0, y0, x1, y1;
        if (lx_map_known_box(&c, &x0, &y0, &x1, &y1)) {
            lx_map_t k;
            if (x1 < x0 || y1 < y0 || x1 >= c.w || y1 >= c.h ||
                lx_map_crop(&c, x0, y0, x1 - x0 + 1, y1 - y0 + 1, &k, err, sizeof err) != 0) { abort(); }
            for (uint32_t y = 0; y < k.h; y++) {
                if (memcmp(k.cell + (size_t)y * k.w, c.cell + (size_t)(y0 + y) * c.w + x0, k.w) != 0) { abort(); }
            }
            lx_map_free(&k);
        }
    }
    lx_map_free(&v);
    lx_map_free(&c);
    return 0;
}
