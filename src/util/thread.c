/*
 * util/thread.c — the parallel loop of thread.h. Threads are started per
 * call: a render runs few loops (prepare, passes), so a persistent pool
 * would buy nothing measurable and would add shutdown paths.
 */
#include "util/thread.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>
#if defined(__x86_64__) || defined(__i386__)
#include <pmmintrin.h>
#include <xmmintrin.h>
#endif

typedef struct Loop {
    ThreadTaskFn fn;
    void *ctx;
    size_t n_tasks;
    atomic_size_t next; /* the next task to hand out */
} Loop;

typedef struct Worker {
    Loop *loop;
    int index;
} Worker;

void thread_set_ftz_daz(void)
{
#if defined(__x86_64__) || defined(__i386__)
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#endif
}

static void *worker_main(void *arg)
{
    Worker *w = arg;
    Loop *loop = w->loop;
    thread_set_ftz_daz();
    for (;;) {
        size_t task = atomic_fetch_add(&loop->next, 1);
        if (task >= loop->n_tasks)
            break;
        loop->fn(loop->ctx, task, w->index);
    }
    return NULL;
}

int thread_parallel_for(int n_workers, size_t n_tasks, ThreadTaskFn fn, void *ctx)
{
    Loop loop = {.fn = fn, .ctx = ctx, .n_tasks = n_tasks};
    atomic_init(&loop.next, 0);
    if (n_workers < 1)
        n_workers = 1;
    if ((size_t)n_workers > n_tasks)
        n_workers = n_tasks > 0 ? (int)n_tasks : 1;
    pthread_t *threads = calloc((size_t)n_workers, sizeof *threads);
    Worker *workers = calloc((size_t)n_workers, sizeof *workers);
    int failed = threads == NULL || workers == NULL;
    int started = 0;
    for (int i = 1; !failed && i < n_workers; i++) {
        workers[i] = (Worker){&loop, i};
        if (pthread_create(&threads[i], NULL, worker_main, &workers[i]) != 0) {
            failed = 1;
            break;
        }
        started = i;
    }
    Worker self = {&loop, 0};
    worker_main(&self);
    for (int i = 1; i <= started; i++)
        pthread_join(threads[i], NULL);
    free(threads);
    free(workers);
    return failed;
}

int thread_count_cores(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)n : 1;
}
