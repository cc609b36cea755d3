/*
 * Textures under threads (shade/texture, OpenImageIO's TextureSystem):
 * eight threads look up three textures with random footprints through one
 * TextureSystem with the smallest budget, opening files and making their
 * MIP levels concurrently; every thread's results must equal the same
 * lookups made alone with an unlimited budget. Run under ThreadSanitizer
 * by `make test-tsan` (OpenImageIO itself is not instrumented).
 */
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "image/image.h"
#include "shade/texture.h"
#include "test.h"

#define TMP RAYES_TEST_TMP "/texture_threads"

enum { THREADS = 8, N = 400, BATCH = 5 };

static const char *const names[3] = {"t_a.exr", "t_b.exr", "t_c.exr"};
static const int sizes[3][2] = {{128, 64}, {45, 45}, {16, 33}};

typedef struct Job {
    TextureSystem *ts;
    uint32_t seed;
    float rgb[N][3];
    float alpha[N];
} Job;

static float unit(uint32_t *x)
{
    *x = *x * 1664525u + 1013904223u;
    return (float)(*x >> 8) / (float)(1u << 24);
}

/* Batches of BATCH points, as grids and hits make them. */
static void *run(void *arg)
{
    Job *job = arg;
    uint32_t x = job->seed;
    for (int i = 0; i < N; i += BATCH) {
        float s[BATCH], t[BATCH], ds[BATCH], dt[BATCH];
        for (int k = 0; k < BATCH; k++) {
            s[k] = 3.0f * unit(&x) - 1.0f;
            t[k] = 3.0f * unit(&x) - 1.0f;
            ds[k] = powf(2.0f, -8.0f * unit(&x));
            dt[k] = powf(2.0f, -8.0f * unit(&x));
        }
        const char *name = names[(i / BATCH) % 3];
        if (texture_lookup(job->ts, name, BATCH, s, t, ds, dt, &job->rgb[i], &job->alpha[i]) != 0)
            job->alpha[i] = -1.0f; /* the comparison will fail */
    }
    return NULL;
}

static void test_threads_match_one_thread(void)
{
    mkdir(TMP, 0755);
    for (int k = 0; k < 3; k++) {
        int w = sizes[k][0], h = sizes[k][1];
        float *img = malloc((size_t)w * h * 4 * sizeof *img);
        for (int i = 0; i < w * h * 4; i++)
            img[i] = (float)((i * 37 + k * 11) % 64) / 64.0f;
        char path[512], err[300];
        snprintf(path, sizeof path, "%s/%s", TMP, names[k]);
        CHECK(image_write_exr(path, w, h, img, err, sizeof err) == RAYES_OK);
        free(img);
    }
    static Job alone[THREADS], together[THREADS];
    TextureSystem *big = texture_system_new(TMP, 1u << 30, 1.0f);
    for (int i = 0; i < THREADS; i++) {
        alone[i] = (Job){.ts = big, .seed = 1000u + (uint32_t)i};
        run(&alone[i]);
    }
    texture_system_free(big);
    TextureSystem *small = texture_system_new(TMP, 60000, 1.0f);
    pthread_t th[THREADS];
    for (int i = 0; i < THREADS; i++) {
        together[i] = (Job){.ts = small, .seed = 1000u + (uint32_t)i};
        CHECK(pthread_create(&th[i], NULL, run, &together[i]) == 0);
    }
    for (int i = 0; i < THREADS; i++)
        pthread_join(th[i], NULL);
    for (int i = 0; i < THREADS; i++) {
        CHECK(memcmp(alone[i].rgb, together[i].rgb, sizeof alone[i].rgb) == 0);
        CHECK(memcmp(alone[i].alpha, together[i].alpha, sizeof alone[i].alpha) == 0);
    }
    TextureStats st;
    texture_get_stats(small, &st);
    CHECK(st.lookups == (uint64_t)THREADS * N);
    CHECK(st.textures == 3 && st.missing == 0);
    texture_system_free(small);
}

TEST_MAIN(TEST(test_threads_match_one_thread))
