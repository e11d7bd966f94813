/* fuzz_tmp.h - a private scratch directory for the file-reading fuzz targets.
 * Loaders that take a path are fuzzed through files written into a per-process directory
 * on /dev/shm (tmpfs: no disk writes), removed at exit. Header-only, test code only. */
#ifndef FUZZ_TMP_H
#define FUZZ_TMP_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char g_fuzz_dir[64];

static void fuzz_tmp_cleanup(void)
{
    char cmd[96];
    if (g_fuzz_dir[0] != '\0' && snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_fuzz_dir) < (int)sizeof cmd) {
        (void)!system(cmd);
    }
}

/* Create the directory once (falls back to /tmp when /dev/shm is missing). */
static const char *fuzz_tmp_dir(void)
{
    if (g_fuzz_dir[0] == '\0') {
        snprintf(g_fuzz_dir, sizeof g_fuzz_dir, "/dev/shm/rfs-fuzz-XXXXXX");
        if (mkdtemp(g_fuzz_dir) == NULL) {
            snprintf(g_fuzz_dir, sizeof g_fuzz_dir, "/tmp/rfs-fuzz-XXXXXX");
            if (mkdtemp(g_fuzz_dir) == NULL) {
                perror("fuzz_tmp_dir");
                abort();
            }
        }
        atexit(fuzz_tmp_cleanup);
    }
    return g_fuzz_dir;
}

/* Write n bytes to DIR/name; returns the full path in a static buffer per slot. */
static const char *fuzz_tmp_write(int slot, const char *name, const void *data, size_t n)
{
    static char paths[2][128];
    snprintf(paths[slot], sizeof paths[slot], "%s/%s", fuzz_tmp_dir(), name);
    FILE *f = fopen(paths[slot], "wb");
    if (f == NULL || (n > 0 && fwrite(data, 1, n, f) != n) || fclose(f) != 0) {
        perror(paths[slot]);
        abort();
    }
    return paths[slot];
}

/* An error from a loader must be exactly one non-empty line (the project's error rule). */
static void fuzz_check_err_line(const char *err)
{
    if (err[0] == '\0' || strchr(err, '\n') != NULL) {
        fprintf(stderr, "bad error message: \"%s\"\n", err);
        abort();
    }
}

#endif /* FUZZ_TMP_H */
