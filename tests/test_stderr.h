/*
 * test_stderr.h — what a call writes on standard error, for tests of
 * warnings (a header of its own: <unistd.h> would clash with tests that
 * name a function read or write).
 */
#ifndef RAYES_TESTS_TEST_STDERR_H
#define RAYES_TESTS_TEST_STDERR_H

#include <stdio.h>
#include <unistd.h>

/* Runs fn with standard error in a file; returns what was written
 * (static, truncated to 8 KiB). */
static inline const char *test_stderr_of(void (*fn)(void *), void *arg)
{
    static char text[8192];
    const char *path = RAYES_TEST_TMP "/test_stderr.txt";
    fflush(stderr);
    int saved = dup(2);
    FILE *f = fopen(path, "w");
    if (!f || saved < 0) {
        if (f)
            fclose(f);
        if (saved >= 0)
            close(saved);
        text[0] = '\0';
        return text;
    }
    dup2(fileno(f), 2);
    fn(arg);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    fclose(f);
    f = fopen(path, "r");
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    text[n] = '\0';
    if (f)
        fclose(f);
    return text;
}

#endif
