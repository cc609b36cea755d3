/*
 * cache_stats.h — what a render's statistics say its cache did, for tests
 * that mean a budget to evict (a data type borrows the budgets the others
 * leave unused, so such a test gives them none and checks it evicted).
 */
#ifndef RAYES_TESTS_CACHE_STATS_H
#define RAYES_TESTS_CACHE_STATS_H

#include <stdio.h>

#include "rayes/rayes.h"

/* The count what ("evictions", "fills", ...) of data type type
 * ("radiosity", "opacity", "irradiance") summed over the resolutions. */
static inline unsigned long long test_cache_count(const RayesStats *st, const char *type,
                                                  const char *what)
{
    static const char *const levels[3] = {"coarse", "medium", "fine"};
    unsigned long long n = 0;
    for (int l = 0; st && l < 3; l++) {
        char name[64];
        snprintf(name, sizeof name, "cache/%s/%s/%s", type, levels[l], what);
        const RayesStat *x = rayes_stats_find(st, name);
        n += x ? x->count : 0;
    }
    return n;
}

/* The entries of data type type evicted. */
static inline unsigned long long test_cache_evictions(const RayesStats *st, const char *type)
{
    return test_cache_count(st, type, "evictions");
}

#endif
