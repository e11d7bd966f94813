/* board.h - STM32F405 board support for the firmware: clocks, time base, watchdog.
 *
 * Clock tree (RM0090 6.2): HSE RFS_BOARD_HSE_HZ (8 MHz) -> PLL (M = HSE/1 MHz, N = 336,
 * P = 2) = 168 MHz SYSCLK; AHB /1, APB1 /4 = 42 MHz (bxCAN), APB2 /2 = 84 MHz; flash
 * 5 wait states. SysTick runs from the core clock and interrupts every millisecond;
 * rfs_board_now_us() combines the millisecond count with the current count down value.
 * The independent watchdog (LSI 32 kHz nominal, /8, reload 1999) fires after 500 ms
 * without rfs_board_kick() (340 .. 940 ms over the LSI's 17 .. 47 kHz range). It must
 * outlast the longest loop iteration: a CONFIG frame's re-initialisation (rfs_app_init,
 * 8.75 million instructions, ~55 ms at 168 MHz; the boot's flood fill is sliced, a period
 * at most 500,000: docs/PERFORMANCE.md); on the 16 MHz HSI fallback (~550 ms) the
 * prescaler is /64 (4 s nominal, rfs_board_iwdg_pr()). While the loop is busy no command is sent and the
 * motor controller's own 200 ms command timeout stops the wheels; once the watchdog has
 * fired, the image boots (rfs_app_init again) and its first command is zero.
 */
#ifndef RFS_BOARD_H
#define RFS_BOARD_H

#include <stdbool.h>
#include <stdint.h>

#ifndef RFS_BOARD_HSE_HZ
#define RFS_BOARD_HSE_HZ 8000000u ///< external crystal, Hz
#endif
#define RFS_BOARD_SYSCLK_HZ 168000000u ///< core clock, Hz
#define RFS_BOARD_HSI_HZ 16000000u     ///< the internal oscillator: the clock without the PLL
#define RFS_BOARD_PCLK1_HZ 42000000u   ///< APB1 clock (bxCAN), Hz
#define RFS_BOARD_IWDG_RELOAD 1999u    ///< 2,000 LSI ticks after the prescaler
#define RFS_BOARD_LSI_MAX_HZ 47000u    ///< the LSI's fastest (datasheet: 17 .. 47 kHz)
/// The longest loop iteration: a CONFIG frame's rfs_app_init (docs/PERFORMANCE.md,
/// "Firmware": 8,751,368 instructions).
#define RFS_BOARD_LONGEST_INSTR 8800000u

/// The independent watchdog's prescaler code for a core at core_hz (RM0090 21.4.2: LSI /
/// 2^(code + 2), 0 .. 6): the smallest from 1 (/8, 500 ms at the nominal 32 kHz) whose
/// shortest timeout, 2,000 ticks of the fastest LSI, outlasts four times the longest
/// iteration at one instruction a cycle (168 MHz: 1, ~210 ms against 340 ms; the 16 MHz
/// HSI fallback: 4, 2.2 s against 2.72 s). That is 2,000 x 2^(code + 2) / 47,000 > 4 x
/// 8.8 M / core_hz, or 2^(code + 2) x core_hz / 1,000 > 827,200: 32 bits (at most 2^8 x
/// 4,294,967), no 64-bit division (libgcc's would cost ~900 B of flash).
static inline uint32_t rfs_board_iwdg_pr(uint32_t core_hz)
{
    _Static_assert(4u * (RFS_BOARD_LONGEST_INSTR / 1000u) * (RFS_BOARD_LSI_MAX_HZ / 1000u) /
                           ((RFS_BOARD_IWDG_RELOAD + 1u) / 1000u) == 827200u,
                   "the bound's constant");
    uint32_t pr = 1u;
    while (pr < 6u && ((core_hz / 1000u) << (pr + 2u)) <= 827200u) {
        pr++;
    }
    return pr;
}

/// Start HSE and the PLL and switch SYSCLK to 168 MHz. Returns 0, or -1 when HSE or
/// the PLL does not become ready (the board then runs on HSI 16 MHz).
int rfs_board_clock_init(void);

/// Start SysTick: one interrupt per millisecond at core_hz.
void rfs_board_time_init(uint32_t core_hz);

/// Microseconds since rfs_board_time_init().
int64_t rfs_board_now_us(void);

/// true when the last reset came from the independent watchdog (then clears the flags).
bool rfs_board_reset_was_watchdog(void);

/// Start the independent watchdog for a core at core_hz (rfs_board_iwdg_pr; it cannot be
/// stopped afterwards).
void rfs_board_watchdog_start(uint32_t core_hz);

/// Reload the watchdog.
void rfs_board_kick(void);

/// Route CAN1 to PB8/PB9 and clock it.
void rfs_board_can_pins(void);

#endif /* RFS_BOARD_H */
