/* hs_err.c - see hs_err.h. */
#include "hs_err.h"

void hs_err_one_line(char *s)
{
    for (char *c = s; *c != '\0'; ++c) {
        if ((unsigned char)*c < 0x20u || *c == 0x7f) {
            *c = '?';
        }
    }
}
