/* stm32f4_regs.h - the few STM32F405 and Cortex-M4 registers the port touches
 * (RM0090 rev 19; ARMv7-M Architecture Reference Manual B3.3 for SysTick). Addresses
 * only: no vendor headers, so the port builds with nothing but arm-none-eabi-gcc. */
#ifndef STM32F4_REGS_H
#define STM32F4_REGS_H

#include <stdint.h>

#define RFS_REG(addr) (*(volatile uint32_t *)(uintptr_t)(addr))

/* RCC, RM0090 7.3 (base 0x40023800). */
#define RCC_CR RFS_REG(0x40023800u)
#define RCC_PLLCFGR RFS_REG(0x40023804u)
#define RCC_CFGR RFS_REG(0x40023808u)
#define RCC_AHB1ENR RFS_REG(0x40023830u)
#define RCC_APB1ENR RFS_REG(0x40023840u)
#define RCC_CSR RFS_REG(0x40023874u)
#define RCC_CR_HSEON (1u << 16)
#define RCC_CR_HSERDY (1u << 17)
#define RCC_CR_PLLON (1u << 24)
#define RCC_CR_PLLRDY (1u << 25)
#define RCC_CFGR_SW_PLL 0x2u
#define RCC_CFGR_SWS_MASK (0x3u << 2)
#define RCC_CFGR_SWS_PLL (0x2u << 2)
#define RCC_AHB1ENR_GPIOBEN (1u << 1)
#define RCC_APB1ENR_CAN1EN (1u << 25)
#define RCC_CSR_RMVF (1u << 24)
#define RCC_CSR_IWDGRSTF (1u << 29)

/* FLASH interface, RM0090 3.9 (base 0x40023C00). */
#define FLASH_ACR RFS_REG(0x40023C00u)

/* GPIOB, RM0090 8.4 (base 0x40020400): CAN1 on PB8 (RX) / PB9 (TX), AF9. */
#define GPIOB_MODER RFS_REG(0x40020400u)
#define GPIOB_AFRH RFS_REG(0x40020424u)

/* IWDG, RM0090 21.4 (base 0x40003000). */
#define IWDG_KR RFS_REG(0x40003000u)
#define IWDG_PR RFS_REG(0x40003004u)
#define IWDG_RLR RFS_REG(0x40003008u)
#define IWDG_SR RFS_REG(0x4000300Cu)
#define IWDG_KEY_RELOAD 0xAAAAu
#define IWDG_KEY_ACCESS 0x5555u
#define IWDG_KEY_START 0xCCCCu

/* SysTick, ARMv7-M B3.3.2. */
#define SYST_CSR RFS_REG(0xE000E010u)
#define SYST_RVR RFS_REG(0xE000E014u)
#define SYST_CVR RFS_REG(0xE000E018u)
#define SYST_CSR_ENABLE (1u << 0)
#define SYST_CSR_TICKINT (1u << 1)
#define SYST_CSR_CLKSOURCE (1u << 2)
#define SYST_CSR_COUNTFLAG (1u << 16)

/* NVIC interrupt set-enable (ARMv7-M B3.4.4); CAN1_RX0 is interrupt 20, CAN1_RX1 21
 * (RM0090 table 61). */
#define NVIC_ISER0 RFS_REG(0xE000E100u)
#define IRQ_CAN1_RX0 20u
#define IRQ_CAN1_RX1 21u

/* SCB application interrupt and reset control (system reset request). */
#define SCB_AIRCR RFS_REG(0xE000ED0Cu)

#endif /* STM32F4_REGS_H */
