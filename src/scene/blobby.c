/*
 * scene/blobby.c — rayes_scene_blobby: a blobby's program compiled and
 * made polygons (geom/blobby.h), added as a polygon mesh of quads with the
 * field's normals (per corner, so creases stay sharp) and the blended
 * primitive variables.
 *
 * The lattice's cube is a sixth of the smallest blob's radius; a surface
 * that would need more than SCENE_BLOBBY_MAX_POINTS points at that size
 * (estimated from the blobs' areas, then as made) gets larger cubes, with
 * one warning.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "geom/blobby.h"
#include "scene/scene.h"
#include "util/log.h"

#define SCENE_BLOBBY_MAX_POINTS ((size_t)1 << 18) /* about 256 k quads: 250 MB of grids */

/* Floats per value of the variables a blobby takes; 0 for the others. */
static int var_size(const char *name)
{
    return !name                     ? 0
           : strcmp(name, "Cs") == 0 ? 3
           : strcmp(name, "Os") == 0 ? 3
           : strcmp(name, "st") == 0 ? 2
                                     : 0;
}

/* Blends each vertex-class variable of pv over the mesh's points: the
 * leaves' values weighted by their fields (their mean where no field
 * reaches). out[k] receives n_points values of pv[k] (NULL for constant
 * ones). Returns 0, or -1 out of memory. */
static int blend(const Blobby *b, const BlobbyMesh *m, size_t n_leaf, const RayesPrimvar *pv,
                 size_t n_pv, float **out)
{
    size_t nl = blobby_leaf_count(b);
    float *w = malloc((nl ? nl : 1) * sizeof *w);
    if (!w)
        return -1;
    for (size_t k = 0; k < n_pv; k++) {
        out[k] = NULL;
        if (pv[k].cls != RAYES_PRIMVAR_VERTEX && pv[k].cls != RAYES_PRIMVAR_VARYING)
            continue;
        size_t size = (size_t)var_size(pv[k].name);
        if (!(out[k] = calloc(m->n_points ? m->n_points * size : 1, sizeof **out))) {
            free(w);
            return -1;
        }
    }
    size_t n = nl < n_leaf ? nl : n_leaf, n_out = 0;
    for (size_t k = 0; k < n_pv; k++)
        n_out += out[k] != NULL;
    for (size_t i = 0; n_out && n && i < m->n_points; i++) {
        blobby_leaf_fields(b, v3_load(m->P + 3 * i), w);
        float sum = 0.0f;
        for (size_t l = 0; l < n; l++)
            sum += w[l] > 0.0f ? w[l] : 0.0f;
        for (size_t k = 0; k < n_pv; k++) {
            if (!out[k])
                continue;
            size_t size = (size_t)var_size(pv[k].name);
            float *o = out[k] + i * size;
            for (size_t l = 0; l < n; l++) {
                float wl = sum > 0.0f ? (w[l] > 0.0f ? w[l] / sum : 0.0f) : 1.0f / (float)n;
                for (size_t c = 0; c < size; c++)
                    o[c] += wl * pv[k].data[l * size + c];
            }
        }
    }
    free(w);
    return 0;
}

RayesError rayes_scene_blobby(RayesScene *s, const RayesBlobby *bl, const RayesPrimvar *pv,
                              size_t n_pv)
{
    if (!s || !bl || (bl->n_code && !bl->code) || (bl->n_floats && !bl->floats) || (n_pv && !pv))
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!scene_finite(bl->floats, bl->n_floats))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "blobby: a float is not finite");
    if (n_pv > 8)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "blobby: too many primitive variables");
    for (size_t k = 0; k < n_pv; k++) {
        int size = var_size(pv[k].name);
        RayesPrimvarClass c = pv[k].cls;
        size_t want = c == RAYES_PRIMVAR_VERTEX || c == RAYES_PRIMVAR_VARYING ? bl->n_leaf : 1;
        if (!size)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "blobby: primitive variable \"%s\"; expected Cs, Os or st",
                              pv[k].name ? pv[k].name : "(null)");
        if ((unsigned)c > RAYES_PRIMVAR_VERTEX || pv[k].count != want || (want && !pv[k].data))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "blobby: \"%s\" has %zu values of class %d; expected 1 (constant, "
                              "uniform) or %zu (varying, vertex)",
                              pv[k].name, pv[k].count, (int)c, bl->n_leaf);
        if (!scene_finite(pv[k].data, pv[k].count * (size_t)size))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "blobby: \"%s\" is not finite",
                              pv[k].name);
    }
    char msg[256];
    Blobby *b = blobby_compile(bl->code, bl->n_code, bl->floats, bl->n_floats, bl->n_strings, msg,
                               sizeof msg);
    if (!b)
        return scene_fail(s,
                          strcmp(msg, "out of memory") == 0 ? RAYES_ERROR_OUT_OF_MEMORY
                                                            : RAYES_ERROR_INVALID_ARGUMENT,
                          "blobby: %s", msg);
    if (blobby_unsupported_count(b))
        log_warning_once("blobby unsupported",
                         "blobby: repelling planes (opcode 1003) and field plugins (1004) are "
                         "not drawn: their fields are taken as 0");
    if (n_pv && blobby_leaf_count(b) != bl->n_leaf)
        log_warning_once("blobby nleaf",
                         "blobby: nleaf is %zu but the program has %zu primitive fields; "
                         "their values blend over the first %zu",
                         bl->n_leaf, blobby_leaf_count(b),
                         bl->n_leaf < blobby_leaf_count(b) ? bl->n_leaf : blobby_leaf_count(b));
    BlobbyMesh m;
    float cell = blobby_default_cell(b), fine = cell;
    double est = blobby_estimate_points(b, cell);
    if (est > (double)SCENE_BLOBBY_MAX_POINTS)
        cell *= (float)sqrt(est / (double)SCENE_BLOBBY_MAX_POINTS);
    int r = blobby_polygonize(b, cell, SCENE_BLOBBY_MAX_POINTS, &m, msg, sizeof msg);
    for (int tries = 0; r == 1 && tries < 8; tries++) {
        cell *= 1.5f;
        r = blobby_polygonize(b, cell, SCENE_BLOBBY_MAX_POINTS, &m, msg, sizeof msg);
    }
    if (r == 0 && cell > fine)
        log_warning("blobby: its surface would need more than %zu points at a sixth of its "
                    "smallest blob's radius (%g); made with cubes of %g",
                    SCENE_BLOBBY_MAX_POINTS, (double)fine, (double)cell);
    if (r != 0) {
        blobby_free(b);
        return scene_fail(s, r < 0 ? RAYES_ERROR_OUT_OF_MEMORY : RAYES_ERROR_INVALID_ARGUMENT,
                          "blobby: %s", r < 0 ? msg : "its surface is too large to make");
    }
    RayesError e = RAYES_OK;
    float *blended[8] = {0};
    RayesPrimvar out[9];
    int *n_verts = malloc((m.n_quads ? m.n_quads : 1) * sizeof *n_verts);
    if (!n_verts || blend(b, &m, bl->n_leaf, pv, n_pv, blended) != 0)
        e = scene_fail(s, RAYES_ERROR_OUT_OF_MEMORY, "blobby: out of memory");
    if (e == RAYES_OK && m.n_quads) {
        /* Counter-clockwise seen from outside, in world space too. */
        const float(*w)[4] = s->world_from_object.m;
        float det = w[0][0] * (w[1][1] * w[2][2] - w[1][2] * w[2][1]) -
                    w[0][1] * (w[1][0] * w[2][2] - w[1][2] * w[2][0]) +
                    w[0][2] * (w[1][0] * w[2][1] - w[1][1] * w[2][0]);
        for (size_t q = 0; q < m.n_quads; q++) {
            n_verts[q] = 4;
            if (det < 0.0f) {
                int t = m.quads[4 * q + 1];
                m.quads[4 * q + 1] = m.quads[4 * q + 3];
                m.quads[4 * q + 3] = t;
                float *n1 = m.corner_N + 12 * q + 3, *n3 = m.corner_N + 12 * q + 9;
                for (int c = 0; c < 3; c++) {
                    float u = n1[c];
                    n1[c] = n3[c], n3[c] = u;
                }
            }
        }
        size_t n_out = 0;
        out[n_out++] = (RayesPrimvar){"N", RAYES_PRIMVAR_FACEVARYING, m.corner_N, 4 * m.n_quads};
        for (size_t k = 0; k < n_pv; k++)
            out[n_out++] =
                blended[k]
                    ? (RayesPrimvar){pv[k].name, RAYES_PRIMVAR_VERTEX, blended[k], m.n_points}
                    : (RayesPrimvar){pv[k].name, RAYES_PRIMVAR_CONSTANT, pv[k].data, 1};
        e = rayes_scene_polygon_mesh_pv(s, m.n_quads, n_verts, m.quads, m.n_points, m.P, out,
                                        n_out);
    }
    for (size_t k = 0; k < n_pv; k++)
        free(blended[k]);
    free(n_verts);
    blobby_mesh_free(&m);
    blobby_free(b);
    return e;
}
