/* startup.c - Cortex-M4 vector table and reset handler for the STM32F405 (RM0090 table
 * 61 for the vector positions). Copies .data from flash, zeroes .bss and .ccm (the
 * core-coupled RAM: its clock is on at reset, RM0090 RCC_AHB1ENR CCMDATARAMEN), calls main().
 * Shared by the hardware image and the emulator image. */
#include <stdint.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _sccm, _eccm, _estack;
int main(void);

void Reset_Handler(void);
void Default_Handler(void);
void NMI_Handler(void) __attribute__((weak, alias("Default_Handler")));
void HardFault_Handler(void) __attribute__((weak, alias("Default_Handler")));
void MemManage_Handler(void) __attribute__((weak, alias("Default_Handler")));
void BusFault_Handler(void) __attribute__((weak, alias("Default_Handler")));
void UsageFault_Handler(void) __attribute__((weak, alias("Default_Handler")));
void SVC_Handler(void) __attribute__((weak, alias("Default_Handler")));
void PendSV_Handler(void) __attribute__((weak, alias("Default_Handler")));
void SysTick_Handler(void) __attribute__((weak, alias("Default_Handler")));
void CAN1_RX0_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));
void CAN1_RX1_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));

/* 16 system exceptions + 82 STM32F405 interrupts: bxCAN's receive FIFOs (the hardware
 * image enables them), the rest unused (polled peripherals). */
__attribute__((section(".isr_vector"), used)) void (*const g_vectors[16 + 82])(void) = {
    (void (*)(void))(uintptr_t)&_estack,
    Reset_Handler,
    NMI_Handler,
    HardFault_Handler,
    MemManage_Handler,
    BusFault_Handler,
    UsageFault_Handler,
    0, 0, 0, 0,
    SVC_Handler,
    0, 0,
    PendSV_Handler,
    SysTick_Handler,
    [16 + 20] = CAN1_RX0_IRQHandler,
    [16 + 21] = CAN1_RX1_IRQHandler,
    /* The other device interrupts default to 0 (never enabled). */
};

void Reset_Handler(void)
{
    uint32_t *src = &_sidata;
    // cppcheck-suppress comparePointers ; _sdata.._edata are one region (linker script)
    for (uint32_t *dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    // cppcheck-suppress comparePointers ; _sbss.._ebss are one region (linker script)
    for (uint32_t *dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0u;
    }
    // cppcheck-suppress comparePointers ; _sccm.._eccm are one region (linker script)
    for (uint32_t *dst = &_sccm; dst < &_eccm;) {
        *dst++ = 0u;
    }
    (void)main();
    for (;;) {
    }
}

/* An unexpected exception: stop here; the watchdog resets the board. */
void Default_Handler(void)
{
    for (;;) {
    }
}
