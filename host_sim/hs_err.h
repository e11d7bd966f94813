/* hs_err.h - error messages of the host loaders stay one line (the project's error rule). */
#ifndef HS_ERR_H
#define HS_ERR_H

/// Replace every control character of the NUL-terminated message `s` (line breaks and
/// tabs from a YAML key, value or file name) by '?', in place, so it prints as one line.
void hs_err_one_line(char *s);

#endif /* HS_ERR_H */
