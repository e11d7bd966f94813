/* lx_err.h - error messages of the host loaders and programs stay one line (the project's
 * error rule: one clear line, whatever the outside text it quotes). */
#ifndef LX_ERR_H
#define LX_ERR_H

/// Replace every control character of the NUL-terminated message `s` (line breaks and
/// tabs from a YAML key, value or file name) by '?', in place, so it prints as one line.
void lx_err_one_line(char *s);

/// Print "prog: MESSAGE\n" on stderr, MESSAGE formatted as by printf (at most 1023
/// bytes) and made one line by lx_err_one_line: option values, option names and file
/// names can hold line breaks.
void lx_err_print(const char *prog, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif /* LX_ERR_H */
