/* fuzz_candump - libFuzzer target for the candump -L line parser (lx_candump.h): a CAN log
 * handed to rfseek-replay is outside input, line by line.
 *
 * Input: any bytes, cut into lines at '\n' as rfseek-replay cuts a log.
 *
 * Beyond ASan/UBSan it checks what lx_candump.h promises:
 *   - a rejected line has a reason;
 *   - an accepted line has a time >= 0, a valid interface name, dlc <= 8 with zero bytes
 *     past it, an 11-bit id unless ext, a 29-bit one always;
 *   - an accepted classic 11-bit data frame formats to a line that parses back to the very
 *     same record (the writer and the reader agree).
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "lx_candump.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_line(const char *s, size_t n)
{
    lx_candump_rec_t r;
    const char *why = NULL;
    if (lx_candump_parse(s, n, &r, &why) != 0) {
        if (why == NULL || why[0] == '\0') {
            abort();
        }
        return;
    }
    if (r.t_us < 0 || !lx_candump_ifname_ok(r.ifname) || r.dlc > 8u || r.id > 0x1FFFFFFFu ||
        (!r.ext && r.id > 0x7FFu)) {
        abort();
    }
    for (unsigned i = r.dlc; i < 8u; i++) {
        if (r.data[i] != 0u) {
            abort();
        }
    }
    if (r.kind != LX_CANDUMP_DATA || r.ext) {
        return;
    }
    rfs_can_frame_t f;
    f.id = r.id;
    f.dlc = r.dlc;
    memcpy(f.data, r.data, 8);
    char line[LX_CANDUMP_FMT_MAX];
    const size_t k = lx_candump_format(line, sizeof line, r.t_us, r.ifname, &f);
    lx_candump_rec_t back;
    if (k == 0u || line[k - 1u] != '\n' || lx_candump_parse(line, k - 1u, &back, &why) != 0 ||
        memcmp(&back, &r, sizeof r) != 0) {
        abort();
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* The parser reads exactly n bytes: a heap copy of each line lets ASan catch a read
     * past its end. */
    size_t pos = 0;
    while (pos < size) {
        const uint8_t *nl = memchr(data + pos, '\n', size - pos);
        const size_t n = nl != NULL ? (size_t)(nl - (data + pos)) : size - pos;
        char *line = malloc(n > 0u ? n : 1u);
        if (line == NULL) {
            return 0;
        }
        memcpy(line, data + pos, n);
        check_line(line, n);
        free(line);
        pos += n + 1u;
    }
    return 0;
}
