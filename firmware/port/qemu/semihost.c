/* semihost.c - ARM semihosting calls (see semihost.h). */
#include "semihost.h"

#include <stddef.h>

/* Operation numbers (semihosting v2, section 5). */
#define SYS_OPEN 0x01u
#define SYS_CLOSE 0x02u
#define SYS_WRITE0 0x04u
#define SYS_WRITE 0x05u
#define SYS_READ 0x06u
#define SYS_GET_CMDLINE 0x15u
#define SYS_EXIT 0x18u
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u
#define ADP_STOPPED_RUNTIME_ERROR 0x20023u

static int32_t call(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return (int32_t)r0;
}

static uint32_t len_of(const char *s)
{
    uint32_t n = 0;
    while (s[n] != '\0') {
        n++;
    }
    return n;
}

int32_t rfs_sh_open(const char *name, uint32_t mode)
{
    const uint32_t a[3] = {(uint32_t)(uintptr_t)name, mode, len_of(name)};
    return call(SYS_OPEN, a);
}

int32_t rfs_sh_read(int32_t fd, void *buf, uint32_t n)
{
    const uint32_t a[3] = {(uint32_t)fd, (uint32_t)(uintptr_t)buf, n};
    const int32_t left = call(SYS_READ, a); /* bytes NOT read */
    if (left < 0 || (uint32_t)left > n) {
        return -1;
    }
    return (int32_t)(n - (uint32_t)left);
}

int32_t rfs_sh_write(int32_t fd, const void *buf, uint32_t n)
{
    const uint32_t a[3] = {(uint32_t)fd, (uint32_t)(uintptr_t)buf, n};
    return call(SYS_WRITE, a) == 0 ? 0 : -1;
}

void rfs_sh_close(int32_t fd)
{
    const uint32_t a[1] = {(uint32_t)fd};
    (void)call(SYS_CLOSE, a);
}

void rfs_sh_puts(const char *s)
{
    (void)call(SYS_WRITE0, s);
}

int32_t rfs_sh_cmdline(char *buf, uint32_t cap)
{
    uint32_t a[2] = {(uint32_t)(uintptr_t)buf, cap};
    return call(SYS_GET_CMDLINE, a) == 0 ? 0 : -1;
}

void rfs_sh_exit(int status)
{
    /* AArch32 SYS_EXIT takes the reason itself in r1: ApplicationExit reads as exit
     * status 0 in qemu, any other reason as 1. */
    (void)call(SYS_EXIT, (const void *)(uintptr_t)(status == 0 ? ADP_STOPPED_APPLICATION_EXIT
                                                               : ADP_STOPPED_RUNTIME_ERROR));
    for (;;) {
    }
}
