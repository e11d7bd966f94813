/* fuzz_radiotap - libFuzzer target for the radiotap + 802.11 parser.
 * Input: one captured record (radiotap header, then the 802.11 frame). Beyond "no
 * out-of-bounds read" (ASan) it checks what the parser promises: a usable header lies
 * inside the input, an address is only reported when the frame holds it, an SSID only
 * when a beacon or probe response holds it, the source-address filter agrees with it, and
 * a parse through a layout memo (kept from the inputs before) equals the walk.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "lx_radiotap.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    lx_rt_frame_t f;
    const int rc = lx_rt_frame_parse(data, size, &f);
    if (rc != 0 && f.rt.status < LX_RT_ERR_SHORT) { abort(); }
    if (rc == 0 && (f.rt.status >= LX_RT_ERR_SHORT || f.rt.it_len < 8 || f.rt.it_len > size)) { abort(); }
    /* An unusable header still locates the 802.11 frame by its length field (Wireshark's
     * way) when that lies in [8, size]. */
    const size_t it_len = rc == 0 ? f.rt.it_len : (size >= 8 ? (size_t)(data[2] | data[3] << 8) : 0u);
    if (it_len < 8 || it_len > size) {
        if (f.wlan_ok) { abort(); }
        return 0;
    }
    const size_t n = size - it_len;
    if (f.frame_len > n) { abort(); }
    if (f.wlan_ok) {
        if (f.wlan.has_sa && (n < 24 || f.wlan.type == LX_WLAN_CTRL)) { abort(); }
        if (f.wlan.has_ta && n < 16) { abort(); }
        if (f.wlan.seq > 4095 || f.wlan.frag > 15 || f.wlan.ds > 3) { abort(); }
        /* An SSID only in a beacon or probe response, inside the frame after its header. */
        if (f.has_ssid && (f.wlan.type != LX_WLAN_MGMT || (f.wlan.subtype != 8 && f.wlan.subtype != 5) ||
                           f.wlan.hdr_len + 14u + f.ssid_len > f.frame_len)) {
            abort();
        }
    } else if (n >= 2) {
        abort();
    }
    /* The feeder's filter ahead of the parse (lx_rt_frame_sa) finds the same source
     * address in every record the parse accepts. */
    const uint8_t *sa = lx_rt_frame_sa(data, size);
    if (sa != NULL && (sa < data || sa + 6 > data + size)) { abort(); }
    if (rc == 0 && ((sa != NULL) != (f.wlan_ok && f.wlan.has_sa) || (sa != NULL && memcmp(sa, f.wlan.sa, 6) != 0))) {
        abort();
    }
    /* Through the layout memo: primed by earlier inputs, then by this one. */
    static lx_rt_layout_t memo;
    for (int i = 0; i < 2; i++) {
        lx_rt_frame_t g;
        if (lx_rt_frame_parse_memo(data, size, &g, &memo) != rc ||
            memcmp(&g, &f, offsetof(lx_rt_frame_t, ssid) + (f.has_ssid ? f.ssid_len : 0u)) != 0) {
            abort();
        }
    }
    /* The parser alone, on every prefix length the record could have been cut at. */
    lx_radiotap_t rt;
    (void)lx_radiotap_parse(data, size / 2, &rt);
    lx_wlan_t w;
    (void)lx_wlan_parse(data, size, &w);
    return 0;
}
