/* fuzz_can - libFuzzer target for the CAN frame decoders and the receiver (common/rfs_can.h).
 * Frames arrive from a bus anyone can write to, so every byte is outside input.
 *
 * Input: a sequence of 12-byte records, each one received frame:
 *   ctrl u8   bit 0: overwrite data[dlc-1] with the correct checksum (so the fuzzer gets
 *             past the CRC and reaches the range, counter, pairing and time checks);
 *             bits 1..3: id = one of our seven ids (0..6: wheel, pose xy, pose th, RSSI,
 *             status, receiver status, config) or the raw 11-bit id below (7);
 *             bit 4 of the first record: the receiver follows the senders' epoch
 *             (follow_epoch) for the whole input
 *   dt   u16  receiver time advance, units of 1 ms (0 .. 65.5 s), little-endian
 *   dlc  u8   taken mod 16 (values > 8 are invalid frames the decoder must reject)
 *   data 8 bytes (data[0..1] also give the raw id for ctrl ids 6..7)
 *
 * Beyond ASan/UBSan it checks what rfs_can.h promises:
 *   - a frame the stateless decoder accepts re-encodes to exactly the same bytes
 *     (the layout has no unused bits: anything else would be a lossy or lax decoder);
 *   - every frame is either accepted or counted in one drop reason (an accepted POSE_XY
 *     may also count the earlier unpaired one as a PAIR drop);
 *   - an accepted RSSI, heartbeat or pose time lies inside [now - max_age, now + max_future]
 *     (with follow_epoch, never after now);
 *   - a complete pose lies inside the int24 millimetre range and (-pi, pi];
 *   - an accepted CONFIG holds a target, strategy, model and P0 floor of the layout.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rfs_can.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const uint32_t k_ids[7] = {RFS_CAN_ID_WHEEL_CMD, RFS_CAN_ID_POSE_XY, RFS_CAN_ID_POSE_TH,
                                  RFS_CAN_ID_RSSI, RFS_CAN_ID_STATUS, RFS_CAN_ID_RX_STATUS,
                                  RFS_CAN_ID_CONFIG};

/* Decode f with the stateless decoder of its id; on success re-encode with the same
 * counter and require identical bytes 0..dlc-1. */
static void check_roundtrip(const rfs_can_frame_t *f)
{
    rfs_can_frame_t g;
    uint8_t c = 0;
    memset(&g, 0, sizeof g);
    switch (f->id) {
    case RFS_CAN_ID_WHEEL_CMD: {
        rfs_can_wheel_t w;
        if (rfs_can_unpack_wheel(f, &w, &c) != RFS_CAN_OK) { return; }
        rfs_can_pack_wheel(&w, c, &g);
        break;
    }
    case RFS_CAN_ID_POSE_XY: {
        rfs_can_pose_t p;
        if (rfs_can_unpack_pose_xy(f, &p, &c) != RFS_CAN_OK) { return; }
        rfs_can_pack_pose_xy(&p, c, &g);
        break;
    }
    case RFS_CAN_ID_POSE_TH: {
        rfs_can_pose_t p;
        if (rfs_can_unpack_pose_th(f, &p, &c) != RFS_CAN_OK) { return; }
        rfs_can_pack_pose_th(&p, c, &g);
        break;
    }
    case RFS_CAN_ID_RSSI: {
        rfs_can_rssi_t r;
        if (rfs_can_unpack_rssi(f, &r, &c) != RFS_CAN_OK) { return; }
        if (r.src >= RFS_CAN_MAX_SOURCES) { abort(); }
        rfs_can_pack_rssi(&r, c, &g);
        break;
    }
    case RFS_CAN_ID_STATUS: {
        rfs_can_status_t s;
        if (rfs_can_unpack_status(f, &s, &c) != RFS_CAN_OK) { return; }
        rfs_can_pack_status(&s, c, &g);
        break;
    }
    case RFS_CAN_ID_RX_STATUS: {
        rfs_can_receiver_t r;
        if (rfs_can_unpack_receiver(f, &r, &c) != RFS_CAN_OK) { return; }
        rfs_can_pack_receiver(&r, c, &g);
        break;
    }
    case RFS_CAN_ID_CONFIG: {
        rfs_can_config_t k;
        if (rfs_can_unpack_config(f, &k, &c) != RFS_CAN_OK) { return; }
        rfs_can_pack_config(&k, c, &g);
        break;
    }
    default:
        return;
    }
    if (c > 15u || g.id != f->id || g.dlc != f->dlc || memcmp(g.data, f->data, f->dlc) != 0) {
        abort();
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rfs_can_rx_t rx;
    rfs_can_rx_cfg_t cfg = rfs_can_rx_cfg_default();
    cfg.follow_epoch = size >= 1u && (data[0] & 0x10u) != 0u;
    if (rfs_can_rx_init(&rx, &cfg) != 0) { abort(); }
    const int64_t future = cfg.follow_epoch ? 0 : cfg.max_future_us;
    /* Start far from 0 so stale and wrapped time stamps are both reachable. */
    int64_t now = 5000000000LL;
    uint32_t n_ok = 0, n_bad = 0;
    for (size_t pos = 0; pos + 12u <= size; pos += 12u) {
        const uint8_t *r = data + pos;
        rfs_can_frame_t f;
        memset(&f, 0, sizeof f);
        const unsigned sel = (r[0] >> 1) & 7u;
        f.dlc = (uint8_t)(r[3] & 0x0Fu);
        memcpy(f.data, r + 4, 8);
        f.id = sel < 7u ? k_ids[sel] : ((uint32_t)r[4] | ((uint32_t)r[5] << 8)) & 0xFFFFu;
        if ((r[0] & 1u) && f.dlc >= 1u && f.dlc <= 8u) {
            f.data[f.dlc - 1u] = rfs_can_checksum(f.id, f.dlc, f.data);
            /* Both checksum implementations must agree on every input. */
            if (rfs_can_checksum_bitwise(f.id, f.dlc, f.data) != rfs_can_checksum(f.id, f.dlc, f.data)) {
                abort();
            }
        }
        now += (int64_t)((uint32_t)r[1] | ((uint32_t)r[2] << 8)) * 1000;
        check_roundtrip(&f);

        rfs_can_msg_t msg;
        memset(&msg, 0, sizeof msg);
        const rfs_can_err_t e = rfs_can_rx_frame(&rx, &f, now, &msg);
        if (e == RFS_CAN_OK) { n_ok++; } else { n_bad++; }
        if ((unsigned)e >= RFS_CAN_NERR || rfs_can_err_str(e) == NULL) { abort(); }
        if (e != RFS_CAN_OK && msg.kind != RFS_CAN_MSG_NONE) { abort(); }
        if (msg.kind == RFS_CAN_MSG_RSSI) {
            if (msg.rssi_t_us < now - cfg.max_age_us || msg.rssi_t_us > now + future ||
                msg.rssi_src >= RFS_CAN_MAX_SOURCES) {
                abort();
            }
        }
        if (msg.kind == RFS_CAN_MSG_RECEIVER &&
            (msg.receiver_t_us < now - cfg.max_age_us || msg.receiver_t_us > now + future)) {
            abort();
        }
        if (msg.kind == RFS_CAN_MSG_CONFIG &&
            (msg.config.target > 1u || msg.config.strategy >= (uint8_t)RFS_SEEK_STRATEGY_COUNT ||
             rfs_can_model_name(msg.config.model) == NULL || msg.config.seed > 0xFFFFFFu ||
             (msg.config.p0_min != RFS_CAN_P0_NONE &&
              (msg.config.p0_min < RFS_CAN_P0_MIN || msg.config.p0_min > RFS_CAN_P0_MAX)))) {
            abort();
        }
        if (msg.kind == RFS_CAN_MSG_POSE) {
            /* int24 mm is +-8388.6 m; theta within (-pi, pi] plus one Q2.13 step. */
            const int64_t lim = (int64_t)8389 << 16;
            if (msg.pose.x > lim || msg.pose.x < -lim || msg.pose.y > lim || msg.pose.y < -lim ||
                msg.pose.theta > 205896 || msg.pose.theta < -205896 ||
                msg.pose.t_us < now - cfg.max_age_us || msg.pose.t_us > now + future) {
                abort();
            }
        }
    }
    /* Conservation: every frame accepted (per message) or dropped (per reason); the only
     * extra drops are unpaired POSE_XY frames superseded by a later accepted one. */
    uint32_t accepted = 0;
    for (unsigned i = 0; i < RFS_CAN_NMSG; i++) { accepted += rx.msg[i].accepted; }
    const uint32_t dropped = rfs_can_rx_dropped_total(&rx);
    if (accepted != n_ok || dropped < n_bad || dropped - n_bad > rx.msg[RFS_CAN_IDX_POSE_XY].accepted) {
        abort();
    }
    return 0;
}
