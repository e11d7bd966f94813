/* feed_writegen - write N radiotap frames through lx_pcap_writer (bench input and the
 * writer's tshark cross-check). Four transmitters take turns in a fixed pseudo-random
 * order; per frame: time 1 ms apart plus jitter, the sender's next sequence number, a
 * signal in [-95, -20] dBm, 2437 MHz or 5180 MHz. Prints the transmitters, one per line.
 * usage: feed_writegen OUT.pcap N
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "lx_pcap.h"

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: feed_writegen OUT.pcap N\n");
        return 2;
    }
    char *end = NULL;
    const unsigned long long n = strtoull(argv[2], &end, 10);
    if (end == argv[2] || *end != '\0') {
        fprintf(stderr, "feed_writegen: N: '%s' is not a count\n", argv[2]);
        return 2;
    }
    static const uint8_t macs[4][6] = {
        {0x02, 0x52, 0x46, 0x53, 0x00, 0x01}, {0x02, 0x52, 0x46, 0x53, 0x00, 0x02},
        {0xb8, 0x27, 0xeb, 0x12, 0x34, 0x56}, {0xdc, 0xa6, 0x32, 0xab, 0xcd, 0xef},
    };
    static const uint8_t bssid[6] = {0x02, 0x00, 0x00, 0x00, 0x00, 0xaa};
    char err[256];
    lx_pcap_writer_t *w = lx_pcap_writer_open(argv[1], err, sizeof(err));
    if (w == NULL) {
        fprintf(stderr, "feed_writegen: %s\n", err);
        return 1;
    }
    uint32_t x = 12345u; /* LCG state: a fixed, reproducible sequence */
    uint16_t seq[4] = {0, 1000, 4090, 77};
    int64_t t = 1700000000000000;
    for (unsigned long long i = 0; i < n; i++) {
        x = x * 1664525u + 1013904223u;
        const unsigned s = (x >> 24) & 3u;
        t += 1000 + (int64_t)((x >> 8) & 255u);
        const int8_t dbm = (int8_t)(-95 + (int)((x >> 12) % 76u));
        seq[s] = (uint16_t)((seq[s] + 1u) & 0x0fffu);
        if (lx_pcap_writer_frame(w, t, macs[s], bssid, seq[s], dbm, s & 1u ? 5180 : 2437) != 0) {
            break;
        }
    }
    if (lx_pcap_writer_close(w) != 0) {
        fprintf(stderr, "feed_writegen: %s: write failed\n", argv[1]);
        return 1;
    }
    for (int s = 0; s < 4; s++) {
        printf("%02x:%02x:%02x:%02x:%02x:%02x\n", macs[s][0], macs[s][1], macs[s][2], macs[s][3],
               macs[s][4], macs[s][5]);
    }
    return 0;
}
