/* lx_err.c - see lx_err.h. */
#include "lx_err.h"

#include <errno.h>
#include <stdbool.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

void lx_err_one_line(char *s)
{
    for (char *c = s; *c != '\0'; ++c) {
        if ((unsigned char)*c < 0x20u || *c == 0x7f) {
            *c = '?';
        }
    }
}

int lx_err_set(char *err, size_t errlen, const char *file, const char *fmt, ...)
{
    if (err != NULL && errlen > 0) {
        char msg[512];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, sizeof msg, fmt, ap);
        va_end(ap);
        if (file != NULL) {
            snprintf(err, errlen, "%s: %s", file, msg);
        } else {
            snprintf(err, errlen, "%s", msg);
        }
        lx_err_one_line(err); /* a file name from a YAML file can hold line breaks */
    }
    return -1;
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

int lx_err_close_stdout(const char *prog, int rc)
{
    errno = 0;
    int bad = fflush(stdout) != 0 || ferror(stdout);
    int e = errno;
    if (fclose(stdout) != 0 && !bad) {
        bad = 1;
        e = errno;
    }
    if (bad) {
        lx_err_print(prog, "stdout: %s", e != 0 ? strerror(e) : "write failed");
        return 1;
    }
    return rc;
}

int lx_err_same_file(const char *prog, const char *in, const char *out)
{
    struct stat si, so;
    if (in != NULL && out != NULL && stat(in, &si) == 0 && stat(out, &so) == 0 &&
        si.st_dev == so.st_dev && si.st_ino == so.st_ino) {
        lx_err_print(prog, "%s: is the input %s (choose another output)", out, in);
        return -1;
    }
    return 0;
}

int lx_err_check_dest(const char *prog, const char *path)
{
    char dir[PATH_MAX];
    if (*path == '\0') { /* "" would be renamed onto from ".tmp..." after all the work */
        lx_err_print(prog, "an output file name is empty");
        return -1;
    }
    const char *slash = strrchr(path, '/');
    if (slash == NULL) {
        snprintf(dir, sizeof dir, ".");
    } else if (slash == path) {
        snprintf(dir, sizeof dir, "/");
    } else if ((size_t)(slash - path) >= sizeof dir) {
        lx_err_print(prog, "%s: %s", path, strerror(ENAMETOOLONG));
        return -1;
    } else {
        memcpy(dir, path, (size_t)(slash - path));
        dir[slash - path] = '\0';
    }
    struct stat st;
    if (stat(dir, &st) != 0) {
        lx_err_print(prog, "%s: %s", path, strerror(errno));
        return -1;
    }
    if (!S_ISDIR(st.st_mode)) {
        lx_err_print(prog, "%s: %s", path, strerror(ENOTDIR));
        return -1;
    }
    if (access(dir, W_OK | X_OK) != 0) {
        lx_err_print(prog, "%s: %s", path, strerror(errno));
        return -1;
    }
    /* Outputs are renamed into place: over a directory that fails after the work, and over
     * a device or FIFO (/dev/null) it would replace the node itself. */
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        lx_err_print(prog, "%s: %s", path,
                     S_ISDIR(st.st_mode) ? strerror(EISDIR)
                                         : "not a regular file (an output is renamed into place, "
                                           "which would replace it)");
        return -1;
    }
    return 0;
}

/* The real path of path's folder and path's last component, or false. */
static bool split_real(const char *path, char *dir, const char **base)
{
    char tmp[PATH_MAX];
    const char *slash = strrchr(path, '/');
    *base = slash ? slash + 1 : path;
    size_t n = slash ? (size_t)(slash - path) : 0;
    if (n >= sizeof tmp) {
        return false;
    }
    memcpy(tmp, path, n);
    tmp[n] = '\0';
    return realpath(slash == path ? "/" : (n ? tmp : "."), dir) != NULL;
}

int lx_err_same_dest(const char *prog, const char *a, const char *b)
{
    char da[PATH_MAX], db[PATH_MAX];
    const char *ba, *bb;
    if (a != NULL && b != NULL && split_real(a, da, &ba) && split_real(b, db, &bb) &&
        strcmp(da, db) == 0 && strcmp(ba, bb) == 0) {
        lx_err_print(prog, "%s: is also written as %s (choose another output)", b, a);
        return -1;
    }
    return lx_err_same_file(prog, a, b);
}

int lx_err_path_opt(const char *prog, const char *opt, const char *value)
{
    if (value[0] != '-') {
        return 0;
    }
    lx_err_print(prog, "%s: '%s' is an option, not a file name (./%s for a file)", opt, value, value);
    return -1;
}
