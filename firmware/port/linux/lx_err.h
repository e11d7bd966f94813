/* lx_err.h - error messages of the host loaders and programs stay one line (the project's
 * error rule: one clear line, whatever the outside text it quotes). */
#ifndef LX_ERR_H
#define LX_ERR_H

#include <stddef.h>

/// Replace every control character of the NUL-terminated message `s` (line breaks and
/// tabs from a YAML key, value or file name) by '?', in place, so it prints as one line.
void lx_err_one_line(char *s);

/// Write "file: MESSAGE" (or MESSAGE when file is NULL) into err (size errlen, may be 0),
/// MESSAGE formatted as by printf (at most 511 bytes) and the whole made one line by
/// lx_err_one_line; returns -1, so a loader can `return lx_err_set(...)`.
int lx_err_set(char *err, size_t errlen, const char *file, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/// Print "prog: MESSAGE\n" on stderr, MESSAGE formatted as by printf (at most 1023
/// bytes) and made one line by lx_err_one_line: option values, option names and file
/// names can hold line breaks.
void lx_err_print(const char *prog, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/// A program's exit through its standard output: flush and close stdout and return rc,
/// or 1 after "prog: stdout: REASON" when a byte written to it was lost (a full disk,
/// /dev/full, a closed pipe). Every program returns through it.
int lx_err_close_stdout(const char *prog, int rc);

/// Refuse an output that is the input itself, whatever the names (same st_dev and
/// st_ino; an output that does not exist yet is another file). 0, or -1 after
/// "prog: OUT: is the input IN (choose another output)".
int lx_err_same_file(const char *prog, const char *in, const char *out);

/// Refuse two outputs that name one file, whether or not it exists yet (their folders'
/// real paths and their last components compared). 0, or -1 after "prog: B: is also
/// written as A (choose another output)". Call after lx_err_check_dest on both.
int lx_err_same_dest(const char *prog, const char *a, const char *b);

/// Check before any work that `path` can be created: its directory exists, is a
/// directory and is writable (the rename into place needs it), and `path` is not an
/// existing directory, device or FIFO (the rename would fail or replace it), nor empty.
/// 0, or -1 after "prog: PATH: REASON".
int lx_err_check_dest(const char *prog, const char *path);

/// Refuse a path-valued option's value that starts with '-': an option taken for the
/// value (`-o --seed 3` would write a file named "--seed"); "./-x" still names such a
/// file. Called while parsing, before any work. 0, or -1 after "prog: OPT: 'VALUE' is an
/// option, not a file name (./VALUE for a file)".
int lx_err_path_opt(const char *prog, const char *opt, const char *value);

#endif /* LX_ERR_H */
