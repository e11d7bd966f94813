/* bench_can.c - work per frame of the CAN codec, for callgrind (tests/wire/bench_wire.sh).
 * Each bench_* function encodes one frame with rfs_can_tx_* and decodes it with
 * rfs_can_rx_frame, REPS times; callgrind counts the instructions inside them. */
#include <stdio.h>

#include "rfs_can.h"

#define REPS 1000

__attribute__((noinline)) static void bench_wheel(rfs_can_tx_t *tx, rfs_can_rx_t *rx)
{
    for (int i = 0; i < REPS; i++) {
        rfs_can_wheel_t w = {(int16_t)i, (int16_t)-i, 0};
        rfs_can_frame_t f;
        rfs_can_msg_t m;
        rfs_can_tx_wheel(tx, &w, &f);
        (void)rfs_can_rx_frame(rx, &f, 0, &m);
    }
}

__attribute__((noinline)) static void bench_pose(rfs_can_tx_t *tx, rfs_can_rx_t *rx)
{
    for (int i = 0; i < REPS; i++) {
        rfs_pose_t core = {(int64_t)i * 100000, i * 655, -i * 655, i * 13};
        rfs_can_pose_t p = rfs_can_pose_from_core(&core);
        rfs_can_frame_t xy, th;
        rfs_can_msg_t m;
        rfs_can_tx_pose(tx, &p, &xy, &th);
        (void)rfs_can_rx_frame(rx, &xy, core.t_us, &m);
        (void)rfs_can_rx_frame(rx, &th, core.t_us, &m);
    }
}

__attribute__((noinline)) static void bench_rssi(rfs_can_tx_t *tx, rfs_can_rx_t *rx)
{
    for (int i = 0; i < REPS; i++) {
        int64_t t = 200000000 + (int64_t)i * 5000;
        rfs_can_rssi_t r = {0, (int8_t)(-60 - i % 20), (uint8_t)i, rfs_can_wrap_time(t)};
        rfs_can_frame_t f;
        rfs_can_msg_t m;
        rfs_can_tx_rssi(tx, &r, &f);
        (void)rfs_can_rx_frame(rx, &f, t, &m);
    }
}

__attribute__((noinline)) static void bench_status(rfs_can_tx_t *tx, rfs_can_rx_t *rx)
{
    for (int i = 0; i < REPS; i++) {
        rfs_can_status_t s = {3, 2, 2, true, false, 0, (uint32_t)i, false};
        rfs_can_frame_t f;
        rfs_can_msg_t m;
        rfs_can_tx_status(tx, &s, &f);
        (void)rfs_can_rx_frame(rx, &f, 0, &m);
    }
}

__attribute__((noinline)) static uint32_t bench_crc_table(const rfs_can_frame_t *f)
{
    uint32_t acc = 0;
    for (int i = 0; i < REPS; i++) {
        acc += rfs_can_checksum(f->id + (uint32_t)(i & 1), f->dlc, f->data);
    }
    return acc;
}

__attribute__((noinline)) static uint32_t bench_crc_bitwise(const rfs_can_frame_t *f)
{
    uint32_t acc = 0;
    for (int i = 0; i < REPS; i++) {
        acc += rfs_can_checksum_bitwise(f->id + (uint32_t)(i & 1), f->dlc, f->data);
    }
    return acc;
}

int main(void)
{
    rfs_can_tx_t tx;
    rfs_can_rx_t rx;
    rfs_can_rx_cfg_t cfg = rfs_can_rx_cfg_default();
    rfs_can_tx_init(&tx);
    rfs_can_rx_init(&rx, &cfg);
    bench_wheel(&tx, &rx);
    bench_pose(&tx, &rx);
    bench_rssi(&tx, &rx);
    bench_status(&tx, &rx);
    const rfs_can_frame_t f8 = {RFS_CAN_ID_RSSI, 8, {1, 2, 3, 4, 5, 6, 7, 0}};
    if (bench_crc_table(&f8) != bench_crc_bitwise(&f8)) {
        return 1;
    }
    uint32_t acc = 0;
    for (int i = 0; i < RFS_CAN_NMSG; i++) {
        acc += rx.msg[i].accepted;
    }
    printf("accepted %u frames, dropped %u\n", acc, rfs_can_rx_dropped_total(&rx));
    return acc == 5u * REPS && rfs_can_rx_dropped_total(&rx) == 0 ? 0 : 1;
}
