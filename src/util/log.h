/*
 * util/log.h — warnings and diagnostics on standard error, and the time
 * and memory readings that statistics use.
 *
 * log_warning_once prints a message once per distinct key for the life of
 * the process (a fixed-size table; thread-safe).
 */
#ifndef RAYES_UTIL_LOG_H
#define RAYES_UTIL_LOG_H

#include <stddef.h>
#include <stdint.h>

void log_warning(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void log_warning_once(const char *key, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Seconds on a monotonic clock. */
double time_now(void);

/* Seconds of CPU the process has used, all threads. */
double time_cpu(void);

/* The process's peak resident set size in bytes (0 if unknown). */
uint64_t mem_peak_rss_bytes(void);
/* The process's resident memory now (0 if unknown), and the machine's
 * physical memory, or its container's limit when lower (UINT64_MAX if
 * unknown), bytes. */
uint64_t mem_rss_bytes(void);
uint64_t mem_physical_bytes(void);

#endif /* RAYES_UTIL_LOG_H */
