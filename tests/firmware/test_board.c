/* test_board.c - the STM32 board's watchdog prescaler (firmware/port/stm32f4/board.h,
 * rfs_board_iwdg_pr) against a double-precision reference: the shortest timeout, 2,000
 * ticks of the fastest LSI (47 kHz) after the prescaler, must outlast four times the
 * longest loop iteration (8.8 M instructions, one a cycle) at the board's clock. */
#include "rfs_test.h"

#include <math.h>

#include "port/stm32f4/board.h"

/* Seconds: the watchdog's shortest timeout with prescaler code pr (LSI / 2^(pr + 2)). */
static double shortest_s(uint32_t pr)
{
    return 2000.0 * pow(2.0, (double)pr + 2.0) / 47000.0;
}

static double need_s(double core_hz)
{
    return 4.0 * 8.8e6 / core_hz;
}

/* The reference: the smallest code from 1 (/8) whose shortest timeout outlasts the need,
 * else the largest (6, /256). */
static uint32_t reference(double core_hz)
{
    for (uint32_t pr = 1; pr < 6; pr++) {
        if (shortest_s(pr) > need_s(core_hz)) {
            return pr;
        }
    }
    return 6;
}

static void test_iwdg_prescaler_at_the_board_clocks(void **state)
{
    (void)state;
    /* 168 MHz: /8 (500 ms nominal, 340 ms shortest against ~210 ms); the 16 MHz HSI: /64
     * (4 s nominal, 2.72 s shortest against 2.2 s: /8 would reset every CONFIG frame). */
    assert_int_equal(rfs_board_iwdg_pr(RFS_BOARD_SYSCLK_HZ), 1);
    assert_int_equal(rfs_board_iwdg_pr(16000000u), 4);
    assert_true(shortest_s(rfs_board_iwdg_pr(16000000u)) > 8.8e6 / 16e6 * 4.0);
}

static void test_iwdg_prescaler_every_clock(void **state)
{
    (void)state;
    for (uint32_t mhz = 1; mhz <= 200; mhz++) {
        const uint32_t hz = mhz * 1000000u;
        const uint32_t pr = rfs_board_iwdg_pr(hz);
        assert_int_equal(pr, reference((double)hz));
        assert_true(pr >= 1 && pr <= 6);
        if (pr < 6) {
            assert_true(shortest_s(pr) > need_s((double)hz));
        }
    }
    assert_int_equal(rfs_board_iwdg_pr(0u), 6); /* no clock: the longest */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_iwdg_prescaler_at_the_board_clocks),
        cmocka_unit_test(test_iwdg_prescaler_every_clock),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
