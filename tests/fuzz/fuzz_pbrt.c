/*
 * tests/fuzz/fuzz_pbrt.c — a libFuzzer target for the pbrt-v4 reader of
 * io/pbrt.h. The reader drives a checking sink that keeps nothing: meshes
 * must have faces of 3 or 4 vertices with indices in range, every number
 * it is given must be finite, every pattern a parameter names must have
 * been defined before (up to the first 256). The file is named inside a directory that
 * does not exist, so Include, Import and plymesh fail cleanly instead of
 * reading whatever lies in the working directory. A failed parse must
 * leave a one-line message.
 *
 * Build: tests/fuzz/CMakeLists.txt (clang, -DRAYES_FUZZ=ON). Run:
 *   fuzz_pbrt -max_total_time=300 -close_fd_mask=2 CORPUS_COPY_DIR
 * with a copy of tests/fuzz/corpus_pbrt/ as the corpus (-close_fd_mask=2
 * silences the reader's warnings).
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_finite(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            abort();
}

static RayesError camera(void *t, const float e[3], const float a[3], const float u[3], float f)
{
    (void)t, (void)e, (void)a, (void)u, (void)f;
    abort(); /* the pbrt reader gives matrices */
}

static RayesError camera_matrix(void *t, const float m[16], RayesProjection p, float fov,
                                const float sw[4])
{
    (void)t, (void)p;
    check_finite(m, 16);
    check_finite(&fov, 1);
    if (sw)
        check_finite(sw, 4);
    return RAYES_OK;
}

static RayesError transform(void *t, const float m[16])
{
    (void)t;
    check_finite(m, 16);
    return RAYES_OK;
}

/* Time: what the reader sends is finite and ordered. */
static RayesError shutter(void *t, float open, float close)
{
    (void)t;
    if (!(open <= close))
        abort();
    return RAYES_OK;
}

static RayesError motion(void *t, size_t n, const float *times, const float (*m)[16])
{
    (void)t;
    if (n < 2 || n > RAYES_MAX_TIMES)
        abort();
    check_finite(times, n);
    check_finite(m[0], 16 * n);
    return RAYES_OK;
}

static RayesError lens(void *t, float radius, float focus)
{
    (void)t;
    if (!(radius >= 0) || !(focus > 0))
        abort();
    return RAYES_OK;
}

/* The patterns defined so far in this input (the first MAX_PATTERNS). */
#define MAX_PATTERNS 256
static char patterns[MAX_PATTERNS][160];
static size_t n_patterns;

static int pattern_known(const char *name)
{
    if (n_patterns > MAX_PATTERNS)
        return 1; /* not tracked */
    for (size_t i = 0; i < n_patterns; i++)
        if (strcmp(patterns[i], name) == 0)
            return 1;
    return 0;
}

static RayesError shader(void *t, const char *name, const RayesParam *p, size_t n)
{
    (void)t;
    if (!name || !name[0])
        abort();
    for (size_t i = 0; i < n; i++) {
        int str = p[i].type == RAYES_PARAM_STRING || p[i].type == RAYES_PARAM_PATTERN;
        if (!p[i].name || (str && !p[i].string))
            abort();
        if (p[i].type == RAYES_PARAM_PATTERN && !pattern_known(p[i].string))
            abort();
        check_finite(p[i].value, 3);
    }
    return RAYES_OK;
}

static RayesError displacement(void *t, const char *name, const RayesParam *p, size_t n)
{
    if (name && !name[0] && n == 0)
        return RAYES_OK; /* none */
    return shader(t, name, p, n);
}

static RayesError pattern(void *t, const char *name, const char *type, const RayesParam *p,
                          size_t n)
{
    if (!name || !name[0] || shader(t, type, p, n) != RAYES_OK)
        abort();
    if (n_patterns < MAX_PATTERNS)
        snprintf(patterns[n_patterns], sizeof patterns[0], "%s", name);
    n_patterns++;
    return RAYES_OK;
}

static RayesError bound(void *t, float b)
{
    (void)t, (void)b;
    return RAYES_OK;
}

static RayesError search(void *t, const char *k, const char *p)
{
    (void)t, (void)k, (void)p;
    return RAYES_OK;
}

static RayesError rate(void *t, float r)
{
    (void)t, (void)r;
    return RAYES_OK;
}

/* Primitive variables: per point (n values), finite. */
static void check_primvars(const RayesPrimvar *pv, size_t n_pv, size_t n)
{
    for (size_t i = 0; i < n_pv; i++) {
        if (pv[i].cls != RAYES_PRIMVAR_VERTEX || pv[i].count != n)
            abort();
        check_finite(pv[i].data, n * (strcmp(pv[i].name, "st") == 0 ? 2 : 3));
    }
}

static RayesError bilinear(void *t, const float P[4][3], const RayesPrimvar *pv, size_t n_pv)
{
    (void)t;
    check_finite(&P[0][0], 12);
    check_primvars(pv, n_pv, 4);
    return RAYES_OK;
}

static RayesError bicubic(void *t, const float P[16][3], const RayesPrimvar *pv, size_t n_pv)
{
    (void)t, (void)pv, (void)n_pv;
    check_finite(&P[0][0], 48);
    return RAYES_OK;
}

static RayesError mesh(void *t, size_t n_faces, const int *nv, const int *idx, size_t n_points,
                       const float *P, const RayesPrimvar *pv, size_t n_pv)
{
    (void)t;
    check_primvars(pv, n_pv, n_points);
    size_t k = 0;
    for (size_t f = 0; f < n_faces; f++) {
        if (nv[f] != 3 && nv[f] != 4)
            abort();
        for (int i = 0; i < nv[f]; i++, k++)
            if (idx[k] < 0 || (size_t)idx[k] >= n_points)
                abort();
    }
    check_finite(P, 3 * n_points);
    return RAYES_OK;
}

static RayesError subdiv(void *t, RayesSubdivScheme scheme, size_t n_faces, const int *nv,
                         const int *idx, size_t n_points, const float *P,
                         const RayesSubdivTags *tags, const RayesPrimvar *pv, size_t n_pv)
{
    (void)tags;
    if (scheme != RAYES_SUBDIV_LOOP)
        abort();
    for (size_t f = 0; f < n_faces; f++)
        if (nv[f] != 3)
            abort();
    return mesh(t, n_faces, nv, idx, n_points, P, pv, n_pv);
}

static RayesError sphere(void *t, float r)
{
    (void)t, (void)r;
    return RAYES_OK;
}

static RayesError quadric(void *t, RayesQuadric type, const float *p, size_t n, unsigned flags)
{
    (void)t, (void)type, (void)flags;
    if (n > 8)
        abort();
    check_finite(p, n);
    return RAYES_OK;
}

static RayesError area(void *t, const float P[4][3], const float L[3])
{
    (void)t;
    check_finite(&P[0][0], 12);
    check_finite(L, 3);
    return RAYES_OK;
}

static RayesError light(void *t, const char *type, const RayesParam *p, size_t n)
{
    return shader(t, type, p, n);
}

static const char *error(void *t)
{
    (void)t;
    return "";
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const IoSink sink = {.set_camera = camera,
                                .set_camera_matrix = camera_matrix,
                                .set_transform = transform,
                                .set_shader = shader,
                                .set_displacement = displacement,
                                .set_displacement_bound = bound,
                                .set_search_path = search,
                                .set_shading_rate = rate,
                                .bilinear_patch = bilinear,
                                .bicubic_patch = bicubic,
                                .polygon_mesh = mesh,
                                .sphere = sphere,
                                .quadric = quadric,
                                .area_light = area,
                                .light = light,
                                .get_error = error,
                                .subdivision_mesh = subdiv,
                                .pattern = pattern,
                                .set_shutter = shutter,
                                .set_transform_motion = motion,
                                .set_camera_motion = motion,
                                .set_depth_of_field = lens};
    n_patterns = 0;
    IoSettings settings;
    io_settings_init(&settings);
    char err[512];
    RayesError e = io_pbrt_parse("/nonexistent-fuzz-dir/fuzz.pbrt", data, size, &sink, NULL,
                                 &settings, err, sizeof err);
    if (e == RAYES_OK && err[0] != '\0')
        abort();
    if (e != RAYES_OK && (err[0] == '\0' || strchr(err, '\n') != NULL))
        abort();
    return 0;
}
