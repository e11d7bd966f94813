/* lx_err.c - see lx_err.h. */
#include "lx_err.h"

#include <stdarg.h>
#include <stdio.h>

void lx_err_one_line(char *s)
{
    for (char *c = s; *c != '\0'; ++c) {
        if ((unsigned char)*c < 0x20u || *c == 0x7f) {
            *c = '?';
        }
    }
}

void lx_err_print(const char *prog, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    lx_err_one_line(msg);
    fprintf(stderr, "%s: %s\n", prog, msg);
}
