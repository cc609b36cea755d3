/*
 * util/check.h — invariant checks. RY_CHECK stays in release builds (cheap
 * invariants whose violation would corrupt memory or images); RY_DCHECK
 * is for debug builds only. A failed check prints file, line and the
 * expression, then aborts: it is a bug in rayes, never bad input.
 */
#ifndef RAYES_UTIL_CHECK_H
#define RAYES_UTIL_CHECK_H

void check_fail(const char *file, int line, const char *expr) __attribute__((noreturn));

#define RY_LIKELY(x) __builtin_expect(!!(x), 1)
#define RY_UNLIKELY(x) __builtin_expect(!!(x), 0)

#define RY_CHECK(x)                                          \
    do {                                                     \
        if (RY_UNLIKELY(!(x)))                               \
            check_fail(__FILE__, __LINE__, #x);              \
    } while (0)

#ifdef NDEBUG
#define RY_DCHECK(x) ((void)0)
#else
#define RY_DCHECK(x) RY_CHECK(x)
#endif

#define RY_ARRAY_SIZE(a) (sizeof(a) / sizeof((a)[0]))
#define RY_MIN(a, b) ((a) < (b) ? (a) : (b))
#define RY_MAX(a, b) ((a) > (b) ? (a) : (b))

#endif /* RAYES_UTIL_CHECK_H */
