/* can_vectors.c - encodes a table of rfseek CAN messages covering every field's range
 * and prints each as "ID#HEXDATA Field=raw ..." (candump compact form plus the values we
 * encoded) for scripts/check_dbc.py, which decodes the bytes with canmatrix and the DBC.
 */
#include <inttypes.h>
#include <stdio.h>

#include "rfs_can.h"

static void print_frame(const rfs_can_frame_t *f)
{
    printf("%03" PRIX32 "#", f->id);
    for (unsigned i = 0; i < f->dlc; i++) {
        printf("%02X", f->data[i]);
    }
}

int main(int argc, char **argv)
{
    (void)argv;
    if (argc > 1) {
        printf("usage: can_vectors\nPrints encoded rfseek CAN frames with their field values.\n");
        return 0;
    }
    rfs_can_frame_t f;
    const int16_t speeds[][2] = {{0, 0}, {-32768, 32767}, {32767, -32768}, {-1, 1}, {700, -700}, {123, 4567}};
    for (unsigned i = 0; i < sizeof speeds / sizeof speeds[0]; i++) {
        rfs_can_wheel_t w = {speeds[i][0], speeds[i][1], (uint8_t)(i & 1u)};
        uint8_t c = (uint8_t)(i * 5u % 16u);
        rfs_can_pack_wheel(&w, c, &f);
        print_frame(&f);
        printf(" Counter=%u Stop=%u LeftSpeed=%d RightSpeed=%d\n", c, w.flags, w.left_mm_s, w.right_mm_s);
    }
    const int32_t pos[][2] = {{0, 0}, {RFS_CAN_POS_MM_MIN, RFS_CAN_POS_MM_MAX}, {RFS_CAN_POS_MM_MAX, RFS_CAN_POS_MM_MIN},
                              {-1, 1}, {12345, -40000}, {40000, 20000}};
    const int16_t th[] = {0, 25736, -25736, -1, 1, 12868};
    const uint32_t ts[] = {0, 0xFFFFFFFFu, 0x80000000u, 1, 123456789u, 0x7FFFFFFFu};
    for (unsigned i = 0; i < sizeof th / sizeof th[0]; i++) {
        rfs_can_pose_t p = {pos[i][0], pos[i][1], th[i], ts[i]};
        uint8_t c = (uint8_t)(15u - i);
        rfs_can_pack_pose_xy(&p, c, &f);
        print_frame(&f);
        printf(" Counter=%u X=%" PRId32 " Y=%" PRId32 "\n", c, p.x_mm, p.y_mm);
        rfs_can_pack_pose_th(&p, c, &f);
        print_frame(&f);
        printf(" Counter=%u Theta=%d Time=%" PRIu32 "\n", c, p.theta_q13, p.t_us32);
    }
    const int8_t dbm[] = {-128, 127, 0, -1, -60, -95};
    const uint8_t seq[] = {0, 255, 128, 1, 77, 254};
    for (unsigned i = 0; i < sizeof dbm / sizeof dbm[0]; i++) {
        rfs_can_rssi_t r = {(uint8_t)(i == 1 ? 15u : i), dbm[i], seq[i], ts[i]};
        uint8_t c = (uint8_t)(i * 3u % 16u);
        rfs_can_pack_rssi(&r, c, &f);
        print_frame(&f);
        printf(" Counter=%u Source=%u Rssi=%d Seq=%u Time=%" PRIu32 "\n", c, r.src, r.dbm, r.seq, r.t_us32);
    }
    for (unsigned i = 0; i < sizeof ts / sizeof ts[0]; i++) {
        rfs_can_receiver_t r = {ts[i]};
        uint8_t c = (uint8_t)(i * 7u % 16u);
        rfs_can_pack_receiver(&r, c, &f);
        print_frame(&f);
        printf(" Counter=%u Time=%" PRIu32 "\n", c, r.t_us32);
    }
    /* CONFIG: every field's limits (P0Min -200 and 100 dBm, no floor; seed 0 and 2^24 - 1;
     * FitEarly keep, off, on). */
    const int16_t p0[] = {RFS_CAN_P0_MIN, RFS_CAN_P0_MAX, RFS_CAN_P0_NONE, -5760};
    const uint32_t seeds[] = {0u, 0xFFFFFFu, 0x123456u, 1u};
    for (unsigned i = 0; i < sizeof p0 / sizeof p0[0]; i++) {
        rfs_can_config_t k = {(uint8_t)(i & 1u), (uint8_t)(i == 1 ? 5u : i), (uint8_t)(i == 0 ? 4u : i),
                              p0[i], seeds[i], (uint8_t)(i % 3u)};
        uint8_t c = (uint8_t)(i * 5u % 16u);
        rfs_can_pack_config(&k, c, &f);
        print_frame(&f);
        printf(" Counter=%u Target=%u FitEarly=%u Strategy=%u Model=%u P0Min=%d Seed=%" PRIu32 "\n", c,
               k.target, k.fit_early, k.strategy, k.model, k.p0_min, k.seed);
    }
    const uint32_t iters[] = {0, 0xFFFFFFFFu, 1, 0x12345678u, 5, 65536};
    for (unsigned i = 0; i < sizeof iters / sizeof iters[0]; i++) {
        rfs_can_status_t s = {(uint8_t)(i % 4u), (uint8_t)((i + 1u) % 4u), (uint8_t)(i % 5u), (i & 1u) != 0,
                              (i & 2u) != 0, (uint8_t)(i == 1 ? 255u : i * 3u), iters[i], (i & 4u) != 0};
        uint8_t c = (uint8_t)(i + 9u) % 16u;
        rfs_can_pack_status(&s, c, &f);
        print_frame(&f);
        printf(" Counter=%u State=%u Kind=%u Relearned=%u LineSearch=%u PrevGoal=%u Configured=%u Faults=%u "
               "Iteration=%" PRIu32 "\n",
               c, s.state, s.kind, s.relearned, s.line_search, s.prev, s.configured, s.faults, s.iteration);
    }
    return 0;
}
