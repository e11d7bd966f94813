/* rfs_assert.h - programmer-error checks for the portable core.
 *
 * Bad input from outside is handled by return codes at the edges; a violated
 * precondition inside the core is a programmer error and goes through
 * rfs_assert_failed(), which the application may replace with its own strong
 * definition (log over CAN, reset, abort(), ...). The default traps.
 */
#ifndef RFS_ASSERT_H
#define RFS_ASSERT_H

/// Called when an RFS_ASSERT fails; weak default traps. Replace it by defining it; it must
/// not return (reset, halt, or abort()).
_Noreturn void rfs_assert_failed(const char *file, int line);

/// Check a programmer-error precondition (never a check on outside input).
#define RFS_ASSERT(cond) \
    do { if (!(cond)) { rfs_assert_failed(__FILE__, __LINE__); } } while (0)

#endif /* RFS_ASSERT_H */
