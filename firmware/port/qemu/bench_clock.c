/* bench_clock.c - SysTick instruction counting for the bench images (see bench_clock.h). */
#include "bench_clock.h"

#include "semihost.h"
#include "stm32f4_regs.h"

/* SysTick wraps every 2^24 ticks (780,190 instructions); the handler counts them. The
 * only mutable state, and it has to be file-level: an interrupt handler takes no
 * arguments. */
static volatile uint32_t s_wraps;

void SysTick_Handler(void);
void SysTick_Handler(void)
{
    s_wraps = s_wraps + 1u;
}

/* Never inlined: every region, the calibration's empty one included, takes the time
 * with the same two calls, so the calibrated overhead is the same everywhere. */
__attribute__((noinline)) uint64_t rfs_bc_ticks(void)
{
    uint32_t w, v;
    do {
        w = s_wraps;
        v = SYST_CVR;
    } while (w != s_wraps);
    return (uint64_t)w * 0x1000000u + (0xFFFFFFu - v);
}

void rfs_bc_put_u64(uint64_t v)
{
    char buf[24];
    int i = 23;
    buf[i] = '\0';
    do {
        buf[--i] = (char)('0' + (int)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    rfs_sh_puts(&buf[i]);
}

void rfs_bc_report(const char *name, uint64_t ticks, uint32_t count)
{
    rfs_sh_puts(name);
    rfs_sh_puts("\t");
    rfs_bc_put_u64(ticks);
    rfs_sh_puts("\t");
    rfs_bc_put_u64(count);
    rfs_sh_puts("\n");
}

static void nops_1000(void)
{
    __asm__ volatile(".rept 1000\n\tnop\n\t.endr" ::: "memory");
}

void rfs_bc_start(void)
{
    SYST_RVR = 0xFFFFFFu;
    SYST_CVR = 0u;
    SYST_CSR = SYST_CSR_ENABLE | SYST_CSR_TICKINT | SYST_CSR_CLKSOURCE;
    /* Calibration: an empty region (the cost of taking the time) and 1,000 NOPs. */
    RFS_BC_MEASURE("calib_empty", 1, (void)0);
    RFS_BC_MEASURE("calib_nop1000", 1000, nops_1000());
}

/* Stack depth of a call: paint the free stack below the caller's SP, run, scan. */
extern uint32_t _sstack;
#define STACK_PAINT 0xA5A5A5A5u

uintptr_t rfs_bc_stack_paint(void)
{
    uintptr_t sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    for (uint32_t *p = &_sstack; (uintptr_t)p < sp - 32u; p++) {
        *p = STACK_PAINT;
    }
    return sp;
}

uint32_t rfs_bc_stack_depth(uintptr_t sp)
{
    const uint32_t *p = &_sstack;
    while ((uintptr_t)p < sp && *p == STACK_PAINT) {
        p++;
    }
    return (uint32_t)(sp - (uintptr_t)p);
}
