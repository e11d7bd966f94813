/* cppcheck_assert.h - seen by cppcheck only (make lint, docs/RELIABILITY.md). RFS_ASSERT's
 * hook never returns (_Noreturn in common/rfs_assert.h), which cppcheck 2.10 does not take
 * into account: a dereference after RFS_ASSERT(p != NULL) would be reported as
 * nullPointerRedundantCheck. Written as the standard assert(), which cppcheck treats as a
 * precondition. The real header is skipped with -DRFS_ASSERT_H. */
#include <assert.h>
#define RFS_ASSERT(cond) assert(cond)
