/*
 * util/log.c — see log.h. The warn-once table is guarded by a mutex; it is
 * small because warnings are rare and named by their kind, not by value.
 */
#include "util/log.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "util/check.h"

static pthread_mutex_t once_lock = PTHREAD_MUTEX_INITIALIZER;
static char once_keys[256][64];
static size_t n_once_keys;

void check_fail(const char *file, int line, const char *expr)
{
    fprintf(stderr, "rayes: internal error: %s:%d: check failed: %s\n", file, line, expr);
    abort();
}

static void vwarn(const char *fmt, va_list ap)
{
    char buf[1024];
    vsnprintf(buf, sizeof buf, fmt, ap);
    fprintf(stderr, "rayes: warning: %s\n", buf);
}

void log_warning(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vwarn(fmt, ap);
    va_end(ap);
}

void log_warning_once(const char *key, const char *fmt, ...)
{
    int seen = 0;
    pthread_mutex_lock(&once_lock);
    for (size_t i = 0; i < n_once_keys && !seen; i++)
        seen = strncmp(once_keys[i], key, sizeof once_keys[i] - 1) == 0;
    if (!seen && n_once_keys < RY_ARRAY_SIZE(once_keys))
        snprintf(once_keys[n_once_keys++], sizeof once_keys[0], "%s", key);
    pthread_mutex_unlock(&once_lock);
    if (seen)
        return;
    va_list ap;
    va_start(ap, fmt);
    vwarn(fmt, ap);
    va_end(ap);
}

double time_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double time_cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

uint64_t mem_rss_bytes(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long size = 0, resident = 0;
    int n = f ? fscanf(f, "%lu %lu", &size, &resident) : 0;
    if (f)
        fclose(f);
    long page = sysconf(_SC_PAGESIZE);
    return n == 2 && page > 0 ? (uint64_t)resident * (uint64_t)page : 0;
}

uint64_t mem_physical_bytes(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    uint64_t bytes = pages > 0 && page > 0 ? (uint64_t)pages * (uint64_t)page : UINT64_MAX;
    /* a container's limit (cgroup v2), when lower: "max" reads as none */
    FILE *f = fopen("/sys/fs/cgroup/memory.max", "r");
    unsigned long long limit;
    if (f && fscanf(f, "%llu", &limit) == 1 && limit < bytes)
        bytes = limit;
    if (f)
        fclose(f);
    return bytes;
}

uint64_t mem_peak_rss_bytes(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0)
        return 0;
    return (uint64_t)ru.ru_maxrss * 1024u; /* Linux reports kilobytes */
}
