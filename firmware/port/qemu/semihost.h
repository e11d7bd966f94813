/* semihost.h - ARM semihosting calls (ARM "Semihosting for AArch32 and AArch64", v2):
 * the emulator image's only I/O. qemu serves them with
 * -semihosting-config enable=on,target=native: files are the host's, relative to
 * qemu's working directory. Called with BKPT 0xAB (Thumb, M profile). */
#ifndef RFS_SEMIHOST_H
#define RFS_SEMIHOST_H

#include <stdint.h>

/// Open a host file; mode 1 = "rb", 5 = "wb" (semihosting SYS_OPEN modes). Returns a
/// handle, or -1.
int32_t rfs_sh_open(const char *name, uint32_t mode);

/// Read up to n bytes. Returns the bytes read (0 at end of file), -1 on error.
int32_t rfs_sh_read(int32_t fd, void *buf, uint32_t n);

/// Write n bytes. Returns 0 when all were written, -1 otherwise.
int32_t rfs_sh_write(int32_t fd, const void *buf, uint32_t n);

/// Close a handle.
void rfs_sh_close(int32_t fd);

/// Write a NUL-terminated string to the debug console (qemu's stderr).
void rfs_sh_puts(const char *s);

/// The command line (qemu: image name and -append text). Returns 0, or -1.
int32_t rfs_sh_cmdline(char *buf, uint32_t cap);

/// Leave the emulator: status 0 reports success, anything else failure.
void rfs_sh_exit(int status) __attribute__((noreturn));

#endif /* RFS_SEMIHOST_H */
