/* rfs_test.h - what every CMocka test includes (cmocka.h needs these first). */
#ifndef RFS_TEST_H
#define RFS_TEST_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#endif /* RFS_TEST_H */
