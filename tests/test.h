/*
 * test.h — the smallest test harness that does the job: CHECK records a
 * failure with file and line and goes on; TEST_MAIN runs the listed tests
 * and prints "N passed, M failed" (the summary line CI reads).
 */
#ifndef RAYES_TESTS_TEST_H
#define RAYES_TESTS_TEST_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static int test_failures;
static int test_checks;

#define CHECK(cond)                                                                    \
    do {                                                                               \
        test_checks++;                                                                 \
        if (!(cond)) {                                                                 \
            test_failures++;                                                           \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);  \
        }                                                                              \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                          \
    do {                                                                               \
        double ca_ = (double)(a), cb_ = (double)(b);                                   \
        test_checks++;                                                                 \
        if (!(fabs(ca_ - cb_) <= (tol))) {                                             \
            test_failures++;                                                           \
            fprintf(stderr, "%s:%d: %s = %.9g, expected %s = %.9g (tolerance %g)\n",   \
                    __FILE__, __LINE__, #a, ca_, #b, cb_, (double)(tol));              \
        }                                                                              \
    } while (0)

typedef void (*TestFn)(void);
typedef struct TestCase {
    const char *name;
    TestFn fn;
    int threaded; /* TEST_THREADS: what ThreadSanitizer is for */
} TestCase;

#define TEST(fn)                                                                                   \
    {                                                                                              \
#fn, fn, 0                                                                                 \
    }
#define TEST_THREADS(fn)                                                                           \
    {                                                                                              \
#fn, fn, 1                                                                                 \
    }

#if defined(__SANITIZE_THREAD__)
#define TEST_UNDER_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define TEST_UNDER_TSAN 1
#endif
#endif

/* Runs the cases in order, printing each one's time. Under
 * ThreadSanitizer, a file that marks some cases TEST_THREADS (the ones
 * whose point is threads: the same bytes on 1 and 2 threads, a tiny cache
 * shared by both) runs only those: the rest check images and numbers that
 * the Release and AddressSanitizer runs check, at a twentieth of the
 * cost. */
static int test_run(const TestCase *cases, size_t n)
{
    int failed_tests = 0, only_threaded = 0, skipped = 0;
#ifdef TEST_UNDER_TSAN
    for (size_t i = 0; i < n; i++)
        only_threaded |= cases[i].threaded;
#endif
    for (size_t i = 0; i < n; i++) {
        if (only_threaded && !cases[i].threaded) {
            printf("skip %s (not a threads test; ThreadSanitizer runs those)\n", cases[i].name);
            skipped++;
            continue;
        }
        int before = test_failures;
        struct timespec t0, t1;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        cases[i].fn();
        clock_gettime(CLOCK_MONOTONIC, &t1);
        int ok = test_failures == before;
        failed_tests += !ok;
        printf("%s %s (%.2f s)\n", ok ? "ok  " : "FAIL", cases[i].name,
               (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
    }
    printf("%zu passed, %d failed (%d checks)", n - skipped - failed_tests, failed_tests,
           test_checks);
    if (skipped)
        printf(", %d skipped", skipped);
    printf("\n");
    return failed_tests ? 1 : 0;
}

/* The faces of an (n + 1) x (n + 1) lattice of points, row by row: 2 n^2
 * triangles, counts in nv (3 each) and corners in idx (6 n^2 ints),
 * wound (i, j), (i + 1, j + 1), (i + 1, j) and (i, j), (i, j + 1),
 * (i + 1, j + 1). */
static inline void test_lattice_triangles(int n, int *nv, int *idx)
{
    int m = n + 1;
    for (int j = 0, f = 0; j < n; j++)
        for (int i = 0; i < n; i++, f += 2) {
            int a = j * m + i, b = a + 1, c = a + m + 1, d = a + m;
            const int tri[6] = {a, c, b, a, d, c};
            for (int k = 0; k < 6; k++)
                idx[3 * f + k] = tri[k];
            nv[f] = nv[f + 1] = 3;
        }
}

/* Writes text to the file at path (a CHECK fails if it cannot be made). */
static inline void test_write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

#define TEST_MAIN(...)                                                                 \
    int main(void)                                                                     \
    {                                                                                  \
        static const TestCase cases[] = {__VA_ARGS__};                                 \
        return test_run(cases, sizeof cases / sizeof cases[0]);                        \
    }

#endif /* RAYES_TESTS_TEST_H */
