/*
 * tests/app/files.h — what the command-line tests ask of the files a run
 * leaves: whether one exists, and whether two hold the same bytes.
 */
#ifndef RAYES_TESTS_APP_FILES_H
#define RAYES_TESTS_APP_FILES_H

#include <stdio.h>
#include <sys/stat.h>

static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* 1 if both files open and hold the same bytes. */
static int same_bytes(const char *a, const char *b)
{
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    int same = fa && fb;
    while (same) {
        int ca = fgetc(fa), cb = fgetc(fb);
        same = ca == cb;
        if (ca == EOF)
            break;
    }
    if (fa)
        fclose(fa);
    if (fb)
        fclose(fb);
    return same;
}

#endif
