/*
 * util/grow.h — room for one more element at the end of a growing array.
 */
#ifndef RAYES_UTIL_GROW_H
#define RAYES_UTIL_GROW_H

#include <stddef.h>
#include <stdlib.h>

/* Makes *array (of *cap elements of elem bytes) hold at least n + 1,
 * doubling its capacity when full. Returns 0, or -1 when out of memory
 * (the array is left as it was). */
static inline int util_grow(void **array, size_t *cap, size_t n, size_t elem)
{
    if (n < *cap)
        return 0;
    size_t c = *cap ? 2 * *cap : 16;
    void *a = realloc(*array, c * elem);
    if (!a)
        return -1;
    *array = a;
    *cap = c;
    return 0;
}

#endif /* RAYES_UTIL_GROW_H */
