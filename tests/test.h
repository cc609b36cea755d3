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
} TestCase;

#define TEST(fn) {#fn, fn}

static int test_run(const TestCase *cases, size_t n)
{
    int failed_tests = 0;
    for (size_t i = 0; i < n; i++) {
        int before = test_failures;
        cases[i].fn();
        int ok = test_failures == before;
        failed_tests += !ok;
        printf("%s %s\n", ok ? "ok  " : "FAIL", cases[i].name);
    }
    printf("%zu passed, %d failed (%d checks)\n", n - failed_tests, failed_tests, test_checks);
    return failed_tests ? 1 : 0;
}

#define TEST_MAIN(...)                                                                 \
    int main(void)                                                                     \
    {                                                                                  \
        static const TestCase cases[] = {__VA_ARGS__};                                 \
        return test_run(cases, sizeof cases / sizeof cases[0]);                        \
    }

#endif /* RAYES_TESTS_TEST_H */
