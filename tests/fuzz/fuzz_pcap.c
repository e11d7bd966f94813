/* fuzz_pcap - libFuzzer target for the capture reader (firmware/port/linux/lx_pcap.h).
 *
 * Input: a whole capture file, classic pcap or pcapng, written to a private tmpfs file and
 * read with lx_pcap_open_offline() and lx_pcap_next() to the end. Beyond ASan/UBSan it
 * checks the header's promises: a refused file or a read error gives one non-empty error
 * line; every packet has caplen bytes of data, nanoseconds below 1 s, and t_us / t_ns equal
 * to ts_sec and ts_nsec (or saturated at INT64_MAX when they do not fit); a classic pcap's
 * seconds fit 32 bits.
 */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_tmp.h"
#include "lx_pcap.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_tmp_write(0, "c.pcap", data, size);
    char err[512] = "";
    lx_pcap_reader_t *r = lx_pcap_open_offline(path, err, sizeof err);
    if (r == NULL) {
        fuzz_check_err_line(err);
        return 0;
    }
    const bool classic = size >= 4 && memcmp(data, "\x0a\x0d\x0d\x0a", 4) != 0;
    for (int k = 0; k < 100000; k++) {
        lx_pcap_pkt_t pkt;
        memset(&pkt, 0, sizeof pkt);
        const int got = lx_pcap_next(r, &pkt, err, sizeof err);
        if (got == 0) { break; }
        if (got < 0) {
            fuzz_check_err_line(err);
            break;
        }
        if (got != 1 || (pkt.caplen > 0 && pkt.data == NULL) || pkt.ts_nsec >= 1000000000u ||
            (classic && pkt.ts_sec > UINT32_MAX)) {
            abort();
        }
        volatile uint8_t sink = 0;
        for (uint32_t i = 0; i < pkt.caplen; i++) { sink ^= pkt.data[i]; }
        (void)sink;
        const bool us_fits = pkt.ts_sec < (uint64_t)INT64_MAX / 1000000u;
        const bool ns_fits = pkt.ts_sec < (uint64_t)INT64_MAX / 1000000000u;
        if ((us_fits ? pkt.t_us != (int64_t)(pkt.ts_sec * 1000000u + pkt.ts_nsec / 1000u) : pkt.t_us != INT64_MAX) ||
            (ns_fits ? pkt.t_ns != (int64_t)(pkt.ts_sec * 1000000000u + pkt.ts_nsec) : pkt.t_ns != INT64_MAX)) {
            abort();
        }
    }
    lx_pcap_close(r);
    return 0;
}
