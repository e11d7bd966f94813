/* feed_count - the floor of bench-feed: read every record of a capture through the
 * libpcap reader (lx_pcap_next, the one adapter to pcap_next_ex) and count them, nothing
 * parsed, nothing written. Prints the record count.
 * usage: feed_count CAPTURE
 */
#include <stdint.h>
#include <stdio.h>

#include "lx_pcap.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: feed_count CAPTURE\n");
        return 2;
    }
    char err[512];
    lx_pcap_reader_t *r = lx_pcap_open_offline(argv[1], err, sizeof(err));
    if (r == NULL) {
        fprintf(stderr, "feed_count: %s\n", err);
        return 1;
    }
    uint64_t n = 0;
    lx_pcap_pkt_t pkt;
    int rc;
    while ((rc = lx_pcap_next(r, &pkt, err, sizeof(err))) == 1) {
        n++;
    }
    lx_pcap_close(r);
    if (rc < 0) {
        fprintf(stderr, "feed_count: %s\n", err);
        return 1;
    }
    printf("%llu\n", (unsigned long long)n);
    return 0;
}
