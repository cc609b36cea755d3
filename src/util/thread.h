/*
 * util/thread.h — a fork-join parallel loop over a pthread pool.
 *
 * thread_parallel_for runs fn(ctx, task, worker) for every task in
 * [0, n_tasks) on n_workers threads (the calling thread is worker 0), hands
 * out tasks in increasing order through an atomic counter, and returns when
 * all are done. Every worker sets flush-to-zero and denormals-are-zero
 * (Embree's requirement) before its first task. Results must not depend on
 * which worker ran a task; workers index per-thread state by `worker`.
 */
#ifndef RAYES_UTIL_THREAD_H
#define RAYES_UTIL_THREAD_H

#include <stddef.h>

typedef void (*ThreadTaskFn)(void *ctx, size_t task, int worker);

/* Returns 0 on success, nonzero if a thread could not be started (the work
 * is then still done, by the threads that did start). */
int thread_parallel_for(int n_workers, size_t n_tasks, ThreadTaskFn fn, void *ctx);

/* The number of online processors (at least 1). */
int thread_count_cores(void);

/* Sets FTZ and DAZ in this thread's floating-point control register. */
void thread_set_ftz_daz(void);

#endif /* RAYES_UTIL_THREAD_H */
