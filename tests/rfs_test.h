/* rfs_test.h - what every CMocka test includes (cmocka.h needs these first). */
#ifndef RFS_TEST_H
#define RFS_TEST_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

/* RFS_TEST_CASE=GLOB in the environment runs only the cases whose names match (cmocka's
 * test filter; `make check T=test_x CASE=GLOB`). Every test's main calls
 * cmocka_run_group_tests, redefined here to set the filter first. */
static inline void rfs_test_filter_from_env(void)
{
    const char *glob = getenv("RFS_TEST_CASE");
    if (glob != NULL && *glob != '\0') {
        cmocka_set_test_filter(glob);
    }
}
#undef cmocka_run_group_tests
#define cmocka_run_group_tests(group_tests, group_setup, group_teardown)                       \
    (rfs_test_filter_from_env(),                                                                \
     _cmocka_run_group_tests(#group_tests, group_tests, sizeof(group_tests) / sizeof((group_tests)[0]), \
                             group_setup, group_teardown))

#endif /* RFS_TEST_H */
