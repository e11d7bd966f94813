/* rfs_assert.c - the weak default assert hook (see rfs_assert.h). */
#include "rfs_assert.h"

__attribute__((weak)) _Noreturn void rfs_assert_failed(const char *file, int line)
{
    (void)file;
    (void)line;
    __builtin_trap();
}
