/* clock_back.c - LD_PRELOAD shim for rfseekd_test.sh: CLOCK_REALTIME is stepped back by
 * RFS_CLOCK_BACK_S seconds (3600) once RFS_CLOCK_AFTER_MS milliseconds (500) of monotonic
 * time have passed since the process first read it (an NTP step on the robot). */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdlib.h>
#include <time.h>

typedef int (*clock_gettime_fn)(clockid_t, struct timespec *);

static long long env_ll(const char *name, long long def)
{
    const char *v = getenv(name);
    return v != NULL ? atoll(v) : def;
}

int clock_gettime(clockid_t id, struct timespec *ts)
{
    static clock_gettime_fn real;
    static struct timespec t0;
    static int have_t0;
    if (real == NULL) {
        real = (clock_gettime_fn)dlsym(RTLD_NEXT, "clock_gettime");
    }
    const int r = real(id, ts);
    if (id != CLOCK_REALTIME || r != 0) {
        return r;
    }
    struct timespec m;
    real(CLOCK_MONOTONIC, &m);
    if (!have_t0) {
        t0 = m;
        have_t0 = 1;
    }
    const long long ms = (m.tv_sec - t0.tv_sec) * 1000LL + (m.tv_nsec - t0.tv_nsec) / 1000000;
    if (ms >= env_ll("RFS_CLOCK_AFTER_MS", 500)) {
        ts->tv_sec -= (time_t)env_ll("RFS_CLOCK_BACK_S", 3600);
    }
    return r;
}
