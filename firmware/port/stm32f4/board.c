/* board.c - STM32F405 clocks, SysTick time base and independent watchdog (board.h). */
#include "board.h"

#include "stm32f4_regs.h"

/* Milliseconds counted by the SysTick interrupt: the one piece of state an interrupt
 * must share with the main loop. */
static volatile uint32_t s_ms_lo;
static volatile uint32_t s_ms_hi;
static uint32_t s_ticks_per_ms;

void SysTick_Handler(void);
void SysTick_Handler(void)
{
    const uint32_t lo = s_ms_lo + 1u;
    if (lo == 0u) {
        s_ms_hi = s_ms_hi + 1u;
    }
    s_ms_lo = lo;
}

static int wait_set(volatile uint32_t *reg, uint32_t mask, uint32_t want)
{
    for (uint32_t i = 0; i < 1000000u; i++) {
        if ((*reg & mask) == want) {
            return 0;
        }
    }
    return -1;
}

int rfs_board_clock_init(void)
{
    RCC_CR |= RCC_CR_HSEON;
    if (wait_set(&RCC_CR, RCC_CR_HSERDY, RCC_CR_HSERDY) != 0) {
        return -1;
    }
    /* RM0090 7.3.2: PLLM = HSE in MHz (1 MHz VCO input), PLLN 336, PLLP /2 (00),
     * PLLQ 7 (48 MHz), source HSE (bit 22). */
    const uint32_t pllm = RFS_BOARD_HSE_HZ / 1000000u;
    RCC_PLLCFGR = pllm | (336u << 6) | (0u << 16) | (1u << 22) | (7u << 24);
    RCC_CR |= RCC_CR_PLLON;
    if (wait_set(&RCC_CR, RCC_CR_PLLRDY, RCC_CR_PLLRDY) != 0) {
        return -1;
    }
    /* 5 wait states at 168 MHz and 3.3 V (RM0090 table 10), prefetch, I- and D-cache. */
    FLASH_ACR = 5u | (1u << 8) | (1u << 9) | (1u << 10);
    /* HPRE /1, PPRE1 /4 (101), PPRE2 /2 (100), then select the PLL. */
    RCC_CFGR = (RCC_CFGR & ~0xFCF3u) | (5u << 10) | (4u << 13) | RCC_CFGR_SW_PLL;
    return wait_set(&RCC_CFGR, RCC_CFGR_SWS_MASK, RCC_CFGR_SWS_PLL);
}

void rfs_board_time_init(uint32_t core_hz)
{
    s_ticks_per_ms = core_hz / 1000u;
    s_ms_lo = 0u;
    s_ms_hi = 0u;
    SYST_RVR = s_ticks_per_ms - 1u;
    SYST_CVR = 0u;
    SYST_CSR = SYST_CSR_ENABLE | SYST_CSR_TICKINT | SYST_CSR_CLKSOURCE;
}

int64_t rfs_board_now_us(void)
{
    uint32_t lo, hi, cvr;
    /* Re-read when the millisecond count moved under us (an interrupt came between). */
    do {
        lo = s_ms_lo;
        hi = s_ms_hi;
        cvr = SYST_CVR;
    } while (lo != s_ms_lo);
    const uint32_t tpm = s_ticks_per_ms != 0u ? s_ticks_per_ms : 1u;
    const uint32_t sub_us = ((tpm - 1u - cvr) * 1000u) / tpm;
    return (int64_t)((((uint64_t)hi << 32) | lo) * 1000u + sub_us);
}

bool rfs_board_reset_was_watchdog(void)
{
    const bool wd = (RCC_CSR & RCC_CSR_IWDGRSTF) != 0u;
    RCC_CSR |= RCC_CSR_RMVF;
    return wd;
}

void rfs_board_watchdog_start(uint32_t core_hz)
{
    IWDG_KR = IWDG_KEY_START;
    IWDG_KR = IWDG_KEY_ACCESS;
    IWDG_PR = rfs_board_iwdg_pr(core_hz);
    IWDG_RLR = RFS_BOARD_IWDG_RELOAD;
    for (uint32_t i = 0; i < 100000u && (IWDG_SR & 3u) != 0u; i++) {
    }
    IWDG_KR = IWDG_KEY_RELOAD;
}

void rfs_board_kick(void)
{
    IWDG_KR = IWDG_KEY_RELOAD;
}

void rfs_board_can_pins(void)
{
    RCC_AHB1ENR |= RCC_AHB1ENR_GPIOBEN;
    RCC_APB1ENR |= RCC_APB1ENR_CAN1EN;
    /* PB8, PB9 alternate function (10), AF9 = CAN1 (RM0090 8.4.10, datasheet table 9). */
    GPIOB_MODER = (GPIOB_MODER & ~(0xFu << 16)) | (0xAu << 16);
    GPIOB_AFRH = (GPIOB_AFRH & ~0xFFu) | 0x99u;
}
