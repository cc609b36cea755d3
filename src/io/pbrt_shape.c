/*
 * io/pbrt_shape.c — the Shape directive (pbrt_internal.h): trianglemesh,
 * bilinearmesh, plymesh (io/ply.h), sphere, cylinder and disk. Every index
 * is checked against the point count before it is used. Winding follows
 * pbrt: flipped by ReverseOrientation and by a transform that swaps
 * handedness. Under an AreaLightSource, up to four quads (or pairs of
 * triangles that make planar convex quads), spheres and disks become rayes
 * area lights of those shapes, other meshes one mesh light each; other
 * emitters are warned about and do not emit.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"
#include "io/ply.h"

/* ------------------------------------------------------------ shapes */

static int swaps_handedness(const double m[16])
{
    return pbrt_mat_det3(m) < 0;
}

static void sub3d(const float *a, const float *b, double o[3])
{
    for (int c = 0; c < 3; c++)
        o[c] = (double)a[c] - b[c];
}

/* A quad's normal (unnormalised): the cross product of its diagonals. */
static void quad_normal(const float *pts, const int *f, double out[3])
{
    double c[3], d[3];
    sub3d(&pts[3 * f[2]], &pts[3 * f[0]], c);
    sub3d(&pts[3 * f[3]], &pts[3 * f[1]], d);
    pbrt_cross3d(c, d, out);
}

/* The world area of faces (fanned) of object-space points pts under the
 * current transform: what an area light's "power" spreads over. */
static double world_area(const Parser *P, size_t n_faces, const int *n_verts, const int *idx,
                         const float *pts)
{
    const double *m = P->gs.ctm;
    double sum = 0;
    const int *f = idx;
    for (size_t i = 0; i < n_faces; f += n_verts[i], i++) {
        double w[64][3];
        int n = n_verts[i] < 64 ? n_verts[i] : 64;
        for (int k = 0; k < n; k++)
            for (int r = 0; r < 3; r++)
                w[k][r] = m[4 * r] * pts[3 * f[k]] + m[4 * r + 1] * pts[3 * f[k] + 1] +
                          m[4 * r + 2] * pts[3 * f[k] + 2] + m[4 * r + 3];
        for (int k = 1; k + 1 < n; k++) {
            double u[3], v[3], c[3];
            for (int r = 0; r < 3; r++)
                u[r] = w[k][r] - w[0][r], v[r] = w[k + 1][r] - w[0][r];
            pbrt_cross3d(u, v, c);
            sum += 0.5 * sqrt(pbrt_dot3d(c, c));
        }
    }
    return sum;
}

/* Emits one emitting quad q (indices into pts; N per vertex or NULL). */
static int emit_area_quad(Parser *P, const Token *t, const float *pts, const float *N,
                          const int q[4])
{
    double g[3], d[3];
    for (int k = 0; k < 4; k++) /* emitters count in the world's bound too */
        pbrt_grow_bound(P, &pts[3 * q[k]], 1);
    quad_normal(pts, q, g);
    memcpy(d, g, sizeof d);
    if (N) {
        for (int c = 0; c < 3; c++)
            d[c] = (double)N[3 * q[0] + c] + N[3 * q[1] + c] + N[3 * q[2] + c] + N[3 * q[3] + c];
        if (pbrt_dot3d(d, d) == 0)
            memcpy(d, g, sizeof d);
    }
    if (P->gs.reverse)
        for (int c = 0; c < 3; c++)
            d[c] = -d[c];
    int flip = (pbrt_dot3d(g, d) < 0) != swaps_handedness(P->gs.ctm);
    for (int side = 0; side < 1 + P->gs.area.twosided; side++) {
        float Q[4][3];
        int rev = flip ^ side;
        for (int k = 0; k < 4; k++)
            memcpy(Q[k], &pts[3 * q[rev ? (4 - k) % 4 : k]], sizeof Q[k]);
        float f[16];
        if (!pbrt_mat_finite(P->gs.ctm))
            return FAIL_TOK(P, t, "the current transform is not finite");
        pbrt_mat_to_float(P->gs.ctm, f);
        RayesError e = P->sink->set_transform(P->sink->target, f);
        if (e == RAYES_OK)
            e = P->sink->area_light(P->sink->target, (const float(*)[3])Q, P->gs.area.L);
        if (e != RAYES_OK)
            return pbrt_sink_failed(P, t, e);
    }
    return 0;
}

/* Nonzero if the triangles a and b share an edge and make a planar convex
 * quad; q gets it in order around. */
static int pair_quad(const float *pts, const int *a, const int *b, int q[4])
{
    for (int i = 0; i < 3; i++) {
        int x = a[i], s1 = a[(i + 1) % 3], s2 = a[(i + 2) % 3];
        for (int j = 0; j < 3; j++)
            if (b[j] == s2 && b[(j + 1) % 3] == s1) {
                int y = b[(j + 2) % 3];
                if (y == x || y == s1 || y == s2)
                    return 0;
                q[0] = x, q[1] = s1, q[2] = y, q[3] = s2;
                double n[4][3], len[4];
                for (int k = 0; k < 4; k++) {
                    double u[3], v[3];
                    sub3d(&pts[3 * q[(k + 1) % 4]], &pts[3 * q[k]], u);
                    sub3d(&pts[3 * q[(k + 3) % 4]], &pts[3 * q[k]], v);
                    pbrt_cross3d(u, v, n[k]);
                    len[k] = sqrt(pbrt_dot3d(n[k], n[k]));
                    if (!(len[k] > 0))
                        return 0;
                }
                for (int k = 1; k < 4; k++)
                    if (pbrt_dot3d(n[0], n[k]) < 0.999 * len[0] * len[k])
                        return 0;
                return 1;
            }
    }
    return 0;
}

/* The most quads an emitter makes quad lights of; more, one mesh light. */
enum { AREA_QUADS = 4 };

/* Whether a face of n corners f (indices into pts) must be wound the other
 * way for its front to be pbrt's: its object-space winding's normal,
 * turned toward the sum of its N when given, reversed by
 * ReverseOrientation and by a transform that swaps handedness. */
static int face_flips(const Parser *P, int n, const int *f, const float *pts, const float *N)
{
    double g[3] = {0, 0, 0}, d[3];
    for (int k = 1; k + 1 < n; k++) { /* the fan's normals, summed */
        double u[3], v[3], c[3];
        sub3d(&pts[3 * f[k]], &pts[3 * f[0]], u);
        sub3d(&pts[3 * f[k + 1]], &pts[3 * f[0]], v);
        pbrt_cross3d(u, v, c);
        for (int j = 0; j < 3; j++)
            g[j] += c[j];
    }
    memcpy(d, g, sizeof d);
    if (N) {
        for (int j = 0; j < 3; j++) {
            d[j] = 0;
            for (int k = 0; k < n; k++)
                d[j] += N[3 * f[k] + j];
        }
        if (pbrt_dot3d(d, d) == 0)
            memcpy(d, g, sizeof d);
    }
    return ((pbrt_dot3d(g, d) < 0) != P->gs.reverse) != swaps_handedness(P->gs.ctm);
}

/* Winds every face of a mesh as face_flips says (idx is rewritten). */
static void orient_faces(const Parser *P, size_t n_faces, const int *n_verts, int *idx,
                         const float *pts, const float *N)
{
    int *f = idx;
    for (size_t i = 0; i < n_faces; f += n_verts[i], i++) {
        int flip = face_flips(P, n_verts[i], f, pts, N);
        for (int k = 1; flip && k < n_verts[i] - k; k++) { /* reverse after the first corner */
            int tmp = f[k];
            f[k] = f[n_verts[i] - k];
            f[n_verts[i] - k] = tmp;
        }
    }
}

/* Emits a mesh's faces as one mesh light: each face wound so that its
 * front is pbrt's (the object-space winding's normal, turned toward the
 * face's N when given, reversed by ReverseOrientation and by a transform
 * that swaps handedness, as emit_area_quad's). idx is rewritten. */
static int emit_area_mesh(Parser *P, const Token *t, size_t n_faces, const int *n_verts, int *idx,
                          size_t n_points, const float *pts, const float *N, const float *uv)
{
    pbrt_grow_bound(P, pts, n_points); /* emitters count in the world's bound too */
    orient_faces(P, n_faces, n_verts, idx, pts, N);
    float m[16];
    if (!pbrt_mat_finite(P->gs.ctm))
        return FAIL_TOK(P, t, "the current transform is not finite");
    pbrt_mat_to_float(P->gs.ctm, m);
    RayesError e = P->sink->set_transform(P->sink->target, m);
    float *st = NULL; /* the image's (s, t): pbrt looks it up at (u, 1 - v) */
    if (e == RAYES_OK && uv && !(st = malloc(2 * n_points * sizeof *st)))
        return FAIL_TOK(P, t, "out of memory");
    for (size_t k = 0; st && k < n_points; k++)
        st[2 * k] = uv[2 * k], st[2 * k + 1] = 1.0f - uv[2 * k + 1];
    if (e == RAYES_OK)
        e = st ? P->sink->area_light_mesh_textured(P->sink->target, n_faces, n_verts, idx, n_points,
                                                   pts, st, P->gs.area.L, P->gs.area.twosided,
                                                   P->gs.area.filename)
               : P->sink->area_light_mesh(P->sink->target, n_faces, n_verts, idx, n_points, pts,
                                          P->gs.area.L, P->gs.area.twosided);
    free(st);
    return e == RAYES_OK ? 0 : pbrt_sink_failed(P, t, e);
}

/* A mesh of triangles and quads (indices checked): an emitter is a few
 * quad lights when its faces are at most AREA_QUADS quads (or triangle
 * pairs that make planar convex quads: sampled as quads, exactly), else
 * one mesh light; other meshes go to polygon_mesh with pbrt's
 * orientation. */
static int shape_mesh(Parser *P, const Token *t, const char *what, size_t n_faces, int *n_verts,
                      int *idx, size_t n_points, const float *pts, const float *N,
                      const float *uv)
{
    if (P->gs.area.on && P->recording) {
        pbrt_warn_at(P, t->line, t->col, "instanced area light",
                     "%s: area lights inside ObjectBegin are not supported (as in pbrt); the shape "
                     "is not emitting",
                     what);
    } else if (P->gs.area.on) {
        pbrt_area_power(P, n_faces, world_area(P, n_faces, n_verts, idx, pts));
        if (P->gs.area.filename[0]) { /* an image over the faces: one textured mesh light */
            if (uv && P->sink->area_light_mesh_textured && P->sink->area_light_mesh)
                return emit_area_mesh(P, t, n_faces, n_verts, idx, n_points, pts, N, uv);
            pbrt_warn_at(P, t->line, t->col, "area image uv",
                         "%s: an area light's image needs the shape's \"uv\" here; it emits "
                         "white (times scale)",
                         what);
        }
        int q[AREA_QUADS][4];
        size_t n_quads = 0, i = 0;
        const int *f = idx;
        for (; i < n_faces && n_quads < AREA_QUADS; f += n_verts[i], i++, n_quads++) {
            if (n_verts[i] == 4) {
                memcpy(q[n_quads], f, sizeof q[n_quads]);
            } else if (i + 1 < n_faces && n_verts[i + 1] == 3 &&
                       pair_quad(pts, f, f + 3, q[n_quads])) {
                f += 3;
                i++;
            } else {
                break;
            }
        }
        if (i < n_faces && P->sink->area_light_mesh)
            return emit_area_mesh(P, t, n_faces, n_verts, idx, n_points, pts, N, NULL);
        if (i < n_faces)
            pbrt_warn_at(P, t->line, t->col, "emitting mesh",
                         "%s: only its first %zu quads emit (the scene takes no mesh lights)", what,
                         n_quads);
        for (size_t k = 0; k < n_quads; k++)
            if (emit_area_quad(P, t, pts, N, q[k]) != 0)
                return -1;
        return 0;
    }
    if (P->shape_bounds) {
        /* a medium's bound: its sides are pbrt's geometric normal's,
         * which faces N when given */
        orient_faces(P, n_faces, n_verts, idx, pts, N);
    } else if (P->gs.reverse != swaps_handedness(P->gs.ctm)) {
        int *f = idx;
        for (size_t i = 0; i < n_faces; f += n_verts[i], i++) {
            int tmp = f[1];
            f[1] = f[n_verts[i] - 1];
            f[n_verts[i] - 1] = tmp;
        }
    }
    return pbrt_emit_mesh(P, t, n_faces, n_verts, idx, n_points, pts, N, uv);
}

/* Points of a "point3 P" parameter as floats (new, free()). */
static float *points_of(Parser *P, const Token *t, const Param *p)
{
    float *pts = malloc((p->n_num ? p->n_num : 1) * sizeof(float));
    if (!pts) {
        FAIL_TOK(P, t, "out of memory");
        return NULL;
    }
    for (size_t i = 0; i < p->n_num; i++)
        pts[i] = (float)p->num[i];
    return pts;
}

static void warn_vertex_data(Parser *P, const Token *t, ParamList *pl, const char *what)
{
    static const char *names[] = {"S", "faceIndices", "emissionfilename"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        Param *p = pbrt_find(pl, names[i]);
        if (p) {
            char key[96];
            snprintf(key, sizeof key, "vertex data %.60s", names[i]);
            pbrt_warn_at(P, p->line, p->col, key, "%s: \"%s\" is not passed on (rayes meshes carry "
                         "positions, N and uv)", what, names[i]);
        }
    }
    (void)t;
}

/* The "point2 uv" (or "st") of a mesh of n_points points, or NULL (with
 * a warning when its count is wrong). */
static Param *uv_param(Parser *P, ParamList *pl, const char *what, size_t n_points)
{
    Param *uv = pbrt_find(pl, "uv");
    if (!uv)
        uv = pbrt_find(pl, "st");
    if (uv && uv->n_num != 2 * n_points) {
        pbrt_warn_at(P, uv->line, uv->col, "uv count", "%s: \"uv\" has %zu values for %zu points; "
                     "ignored", what, uv->n_num, n_points);
        return NULL;
    }
    return uv;
}

/* pbrt-v3's heightfield (v4 dropped it): nu x nv heights Pz over the
 * unit square, x = i / (nu - 1) and y = j / (nv - 1), as a mesh of two
 * triangles a cell with uv = (x, y), as pbrt-v3 refines it. At most 2^24
 * points. */
static int shape_heightfield(Parser *P, const Token *t, ParamList *pl)
{
    double nu = pbrt_get_float(pl, "nu", 0.0), nv = pbrt_get_float(pl, "nv", 0.0);
    Param *pz = pbrt_find(pl, "Pz");
    if (!(nu >= 2 && nv >= 2 && nu == floor(nu) && nv == floor(nv) && nu * nv <= 16777216.0))
        return FAIL_TOK(P, t,
                        "heightfield: expected integer nu and nv of at least 2 (at most "
                        "2^24 points)");
    size_t w = (size_t)nu, h = (size_t)nv, n_points = w * h;
    if (!pz || pz->n_num != n_points)
        return FAIL_TOK(P, t, "heightfield: expected \"float Pz\" with nu nv = %zu values",
                        n_points);
    size_t n_faces = 2 * (w - 1) * (h - 1);
    float *pts = malloc(3 * n_points * sizeof *pts), *uv = malloc(2 * n_points * sizeof *uv);
    int *nvs = malloc(n_faces * sizeof *nvs), *idx = malloc(3 * n_faces * sizeof *idx);
    int r = -1;
    if (!pts || !uv || !nvs || !idx) {
        FAIL_TOK(P, t, "out of memory");
    } else {
        for (size_t j = 0; j < h; j++)
            for (size_t i = 0; i < w; i++) {
                size_t k = j * w + i;
                pts[3 * k] = uv[2 * k] = (float)i / (float)(w - 1);
                pts[3 * k + 1] = uv[2 * k + 1] = (float)j / (float)(h - 1);
                pts[3 * k + 2] = (float)pz->num[k];
            }
        size_t f = 0;
        for (size_t j = 0; j + 1 < h; j++)
            for (size_t i = 0; i + 1 < w; i++) {
                int a = (int)(j * w + i), b = a + 1, c = a + (int)w + 1, d = a + (int)w;
                const int tri[6] = {a, b, c, a, c, d};
                memcpy(&idx[3 * f], tri, sizeof tri);
                nvs[f++] = 3, nvs[f++] = 3;
            }
        r = shape_mesh(P, t, "heightfield", n_faces, nvs, idx, n_points, pts, NULL, uv);
    }
    free(pts);
    free(uv);
    free(nvs);
    free(idx);
    return r;
}

static int shape_trianglemesh(Parser *P, const Token *t, ParamList *pl)
{
    Param *pp = pbrt_find(pl, "P"), *ip = pbrt_find(pl, "indices"), *np = pbrt_find(pl, "N");
    warn_vertex_data(P, t, pl, "trianglemesh");
    if (!pp || pp->n_num < 9)
        return FAIL_TOK(P, t, "trianglemesh: expected \"point3 P\" with at least 3 points");
    size_t n_points = pp->n_num / 3;
    if (!ip && n_points != 3)
        return FAIL_TOK(P, t, "trianglemesh: expected \"integer indices\" (P has %zu points)",
                        n_points);
    size_t n_idx = ip ? ip->n_num : 3;
    if (n_idx % 3 != 0 || n_idx == 0)
        return pbrt_fail_at(P, ip->line, ip->col, "trianglemesh: expected a multiple of 3 indices, "
                            "found %zu", n_idx);
    for (size_t i = 0; ip && i < n_idx; i++)
        if (ip->num[i] < 0 || ip->num[i] >= (double)n_points)
            return pbrt_fail_at(P, ip->line, ip->col,
                                "trianglemesh: index %zu is %.0f but P has %zu points", i,
                                ip->num[i], n_points);
    if (np && np->n_num != pp->n_num) {
        pbrt_warn_at(P, np->line, np->col, "N count",
                     "trianglemesh: \"N\" has %zu values, P %zu; N ignored", np->n_num, pp->n_num);
        np = NULL;
    }
    Param *uvp = uv_param(P, pl, "trianglemesh", n_points);
    size_t n_faces = n_idx / 3;
    float *pts = points_of(P, t, pp);
    float *N = np ? points_of(P, t, np) : NULL;
    float *uv = uvp ? points_of(P, t, uvp) : NULL;
    int *nv = malloc(n_faces * sizeof(int)), *idx = malloc(n_idx * sizeof(int));
    int r = -1;
    if (!pts || (np && !N) || (uvp && !uv) || !nv || !idx) {
        FAIL_TOK(P, t, "out of memory");
    } else {
        for (size_t f = 0; f < n_faces; f++)
            nv[f] = 3;
        for (size_t i = 0; i < n_idx; i++)
            idx[i] = ip ? (int)ip->num[i] : (int)i;
        r = shape_mesh(P, t, "trianglemesh", n_faces, nv, idx, n_points, pts, N, uv);
    }
    free(pts);
    free(N);
    free(uv);
    free(nv);
    free(idx);
    return r;
}

/* loopsubdiv: the Loop limit surface of a triangle mesh, diced like every
 * surface ("levels", v3's "nlevels", is pbrt's fixed refinement, not needed). */
static int shape_loopsubdiv(Parser *P, const Token *t, ParamList *pl)
{
    Param *pp = pbrt_find(pl, "P"), *ip = pbrt_find(pl, "indices"), *lv = pbrt_find(pl, "levels");
    (void)lv; /* read, so it is not reported as unused */
    (void)pbrt_find(pl, "nlevels"); /* pbrt-v3's name for it */
    if (!pp || pp->n_num < 9 || pp->n_num % 3 != 0)
        return FAIL_TOK(P, t, "loopsubdiv: expected \"point3 P\" with at least 3 points");
    size_t n_points = pp->n_num / 3;
    if (!ip || ip->n_num == 0 || ip->n_num % 3 != 0)
        return FAIL_TOK(P, t, "loopsubdiv: expected \"integer indices\", a multiple of 3");
    for (size_t i = 0; i < ip->n_num; i++)
        if (ip->num[i] < 0 || ip->num[i] >= (double)n_points)
            return pbrt_fail_at(P, ip->line, ip->col,
                                "loopsubdiv: index %zu is %.0f but P has %zu points", i, ip->num[i],
                                n_points);
    if (P->gs.area.on)
        pbrt_warn_at(P, t->line, t->col, "loopsubdiv area",
                     "loopsubdiv: area lights are quads in rayes; the surface does not emit");
    size_t n_idx = ip->n_num, n_faces = n_idx / 3;
    Param *uvp = uv_param(P, pl, "loopsubdiv", n_points);
    float *pts = points_of(P, t, pp), *uv = uvp ? points_of(P, t, uvp) : NULL;
    int *nv = malloc(n_faces * sizeof(int)), *idx = malloc(n_idx * sizeof(int));
    int r = -1;
    if (!pts || (uvp && !uv) || !nv || !idx) {
        FAIL_TOK(P, t, "out of memory");
    } else {
        int flip = P->gs.reverse != swaps_handedness(P->gs.ctm);
        for (size_t f = 0; f < n_faces; f++) {
            nv[f] = 3;
            for (int c = 0; c < 3; c++)
                idx[3 * f + (size_t)(flip && c ? 3 - c : c)] = (int)ip->num[3 * f + (size_t)c];
        }
        r = pbrt_emit_subdiv(P, t, n_faces, nv, idx, n_points, pts, uv);
    }
    free(pts);
    free(uv);
    free(nv);
    free(idx);
    return r;
}

static int shape_bilinearmesh(Parser *P, const Token *t, ParamList *pl)
{
    Param *pp = pbrt_find(pl, "P"), *ip = pbrt_find(pl, "indices"), *np = pbrt_find(pl, "N");
    warn_vertex_data(P, t, pl, "bilinearmesh");
    if (!pp || pp->n_num < 12)
        return FAIL_TOK(P, t, "bilinearmesh: expected \"point3 P\" with at least 4 points");
    size_t n_points = pp->n_num / 3;
    if (!ip && n_points != 4)
        return FAIL_TOK(P, t, "bilinearmesh: expected \"integer indices\" (P has %zu points)",
                        n_points);
    size_t n_idx = ip ? ip->n_num : 4;
    if (n_idx % 4 != 0)
        return pbrt_fail_at(P, ip->line, ip->col, "bilinearmesh: expected a multiple of 4 indices, "
                            "found %zu", n_idx);
    for (size_t i = 0; ip && i < n_idx; i++)
        if (ip->num[i] < 0 || ip->num[i] >= (double)n_points)
            return pbrt_fail_at(P, ip->line, ip->col,
                                "bilinearmesh: index %zu is %.0f but P has %zu points", i,
                                ip->num[i], n_points);
    if (np && np->n_num != pp->n_num) {
        pbrt_warn_at(P, np->line, np->col, "N count",
                     "bilinearmesh: \"N\" has %zu values, P %zu; N ignored", np->n_num, pp->n_num);
        np = NULL;
    }
    Param *uvp = uv_param(P, pl, "bilinearmesh", n_points);
    float *pts = points_of(P, t, pp);
    if (!pts)
        return -1;
    if (P->gs.area.on && !P->recording) { /* "power": per patch, over their area */
        double area = 0;
        for (size_t f = 0; f < n_idx / 4; f++) {
            int v[4], nv = 4;
            for (int k = 0; k < 4; k++) /* around the patch: p00 p10 p11 p01 */
                v[k] = ip ? (int)ip->num[4 * f + (size_t)(k < 2 ? k : 5 - k)] : (k < 2 ? k : 5 - k);
            area += world_area(P, 1, &nv, v, pts);
        }
        pbrt_area_power(P, n_idx / 4, area);
    }
    int textured = P->gs.area.filename[0] && P->sink->area_light_mesh_textured;
    if (P->gs.area.on && !P->recording && (n_idx / 4 > AREA_QUADS || textured) &&
        P->sink->area_light_mesh) {
        /* many emitting patches, or an image over them: one mesh light of
         * their corners, around */
        size_t n_faces = n_idx / 4;
        int *nv = malloc(n_faces * sizeof *nv), *idx = malloc(n_idx * sizeof *idx);
        float *N = np ? points_of(P, t, np) : NULL;
        /* the image's uv: the mesh's, or a lone patch's default (pbrt's
         * (0, 0) (1, 0) (0, 1) (1, 1) at p00 p10 p01 p11) */
        float *uv = textured && (uvp || n_points == 4) ? malloc(2 * n_points * sizeof *uv) : NULL;
        int r = -1;
        if (!nv || !idx || (np && !N) || (textured && (uvp || n_points == 4) && !uv)) {
            FAIL_TOK(P, t, "out of memory");
        } else {
            static const int around[4] = {0, 1, 3, 2};
            for (size_t f = 0; f < n_faces; f++) {
                nv[f] = 4;
                for (int k = 0; k < 4; k++)
                    idx[4 * f + (size_t)k] =
                        ip ? (int)ip->num[4 * f + (size_t)around[k]] : around[k];
            }
            for (size_t k = 0; uv && k < 2 * n_points; k++)
                uv[k] = uvp ? (float)uvp->num[k] : (float)((k & 1) ? k / 4 : (k / 2) % 2);
            if (textured && !uv)
                pbrt_warn_at(P, t->line, t->col, "area image uv",
                             "bilinearmesh: an area light's image needs the shape's \"uv\" "
                             "here; it emits white (times scale)");
            r = emit_area_mesh(P, t, n_faces, nv, idx, n_points, pts, N, uv);
        }
        free(uv);
        free(nv);
        free(idx);
        free(N);
        free(pts);
        return r;
    }
    int flip = P->gs.reverse != swaps_handedness(P->gs.ctm);
    int emits = P->gs.area.on && !P->recording;
    /* emitting quads face as N, and so do a medium's bound's patches */
    float *N = (emits || P->shape_bounds) && np ? points_of(P, t, np) : NULL;
    if ((emits || P->shape_bounds) && np && !N) {
        free(pts);
        return -1;
    }
    for (size_t f = 0; f < n_idx / 4; f++) {
        int v[4];
        for (int k = 0; k < 4; k++)
            v[k] = ip ? (int)ip->num[4 * f + k] : k;
        int r;
        if (emits) {
            int q[4] = {v[0], v[1], v[3], v[2]}; /* around the patch */
            r = emit_area_quad(P, t, pts, N, q);
        } else {
            Op patch = {.patch_pv = (np ? 1 : 0) | (uvp ? 2 : 0)};
            static const int order[2][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}};
            int q[4] = {v[0], v[1], v[3], v[2]}; /* around the patch */
            int turn = P->shape_bounds && N ? face_flips(P, 4, q, pts, N) : flip;
            for (int k = 0; k < 4; k++) {
                size_t j = (size_t)v[order[turn][k]];
                memcpy(patch.patch[k], &pts[3 * j], sizeof patch.patch[k]);
                for (int c = 0; c < 3 && np; c++)
                    patch.patch_N[k][c] = (float)np->num[3 * j + (size_t)c];
                for (int c = 0; c < 2 && uvp; c++)
                    patch.patch_uv[k][c] = (float)uvp->num[2 * j + (size_t)c];
            }
            r = pbrt_emit_patch(P, t, &patch);
        }
        if (r != 0) {
            free(pts);
            free(N);
            return -1;
        }
    }
    free(pts);
    free(N);
    return 0;
}

static int shape_plymesh(Parser *P, const Token *t, ParamList *pl)
{
    const char *file = pbrt_get_string(pl, "filename", NULL);
    if (!file)
        return FAIL_TOK(P, t, "plymesh: expected \"string filename\"");
    /* pbrt-v4 refines the mesh to "edgelength" and moves its vertices;
     * rayes dices it by the shading rate and displaces the grids (the
     * caller restores the material after the shape) */
    if (pbrt_shape_displacement(P, t, pl, &P->gs.material) != 0)
        return -1;
    pbrt_find(pl, "edgelength");
    char path[PBRT_PATH], err[600];
    if (pbrt_resolve(P, t, file, path, sizeof path) != 0)
        return -1;
    PlyMesh m;
    if (io_ply_read(path, &m, err, sizeof err) != RAYES_OK)
        return FAIL_TOK(P, t, "plymesh: %s", err);
    if (m.n_bad_normals)
        pbrt_warn_at(P, t->line, t->col, "ply normals",
                     "plymesh: %s: %zu vertex normal(s) not finite or zero; their faces' "
                     "normals are used",
                     path, m.n_bad_normals);
    int r = shape_mesh(P, t, "plymesh", m.n_faces, m.n_verts, m.indices, m.n_vertices, m.P, m.N,
                       m.uv);
    io_ply_mesh_fini(&m);
    return r;
}

/* An emitting sphere or disk: rayes' "arealight" of that shape. */
static int quadric_light(Parser *P, const Token *t, const char *shape, float radius,
                         const double m[16])
{
    RayesParam lp[4] = {
        {.name = "shape", .type = RAYES_PARAM_STRING, .string = shape},
        {.name = "radius", .type = RAYES_PARAM_FLOAT, .value = {radius}},
        {.name = "lightcolor", .type = RAYES_PARAM_COLOR},
        {.name = "intensity", .type = RAYES_PARAM_FLOAT, .value = {1}},
    };
    memcpy(lp[2].value, P->gs.area.L, sizeof lp[2].value);
    return pbrt_emit_light(P, t, m, "arealight", lp, 4);
}

/* pbrt-v3's cone, paraboloid and hyperboloid (v4 dropped them): the
 * quadrics RenderMan's Cone, Paraboloid and Hyperboloid make, which pbrt's
 * are (cone: "radius" 1, "height" 1; paraboloid: "radius" 1, "zmin" 0,
 * "zmax" 1; hyperboloid: "point p1" (0 0 0), "point p2" (1 1 1); each
 * "phimax" 360). Under an area light they warn and do not emit. */
static int shape_v3_quadric(Parser *P, const Token *t, const char *type, ParamList *pl)
{
    double phimax = pbrt_get_float(pl, "phimax", 360.0);
    if (!(phimax > 0 && phimax <= 360))
        return FAIL_TOK(P, t, "%s: expected phimax in (0, 360], found %g", type, phimax);
    float qp[7];
    size_t n;
    RayesQuadric q;
    if (strcmp(type, "cone") == 0) {
        q = RAYES_QUADRIC_CONE, n = 3;
        qp[0] = (float)pbrt_get_float(pl, "height", 1.0);
        qp[1] = (float)pbrt_get_float(pl, "radius", 1.0);
    } else if (strcmp(type, "paraboloid") == 0) {
        q = RAYES_QUADRIC_PARABOLOID, n = 4;
        qp[0] = (float)pbrt_get_float(pl, "radius", 1.0);
        qp[1] = (float)pbrt_get_float(pl, "zmin", 0.0);
        qp[2] = (float)pbrt_get_float(pl, "zmax", 1.0);
    } else {
        static const double origin[3] = {0, 0, 0}, ones[3] = {1, 1, 1};
        const double *p1 = pbrt_get_point(pl, "p1"), *p2 = pbrt_get_point(pl, "p2");
        p1 = p1 ? p1 : origin, p2 = p2 ? p2 : ones;
        q = RAYES_QUADRIC_HYPERBOLOID, n = 7;
        for (int k = 0; k < 3; k++)
            qp[k] = (float)p1[k], qp[3 + k] = (float)p2[k];
    }
    qp[n - 1] = (float)phimax;
    if (P->gs.area.on)
        pbrt_warn_at(P, t->line, t->col, "v3 quadric light",
                     "%s: this emitter is not supported; the shape does not emit", type);
    return pbrt_emit_quadric(P, t, q, qp, n, P->gs.reverse ? RAYES_QUADRIC_REVERSE : 0);
}

static int shape_quadric(Parser *P, const Token *t, const char *type, ParamList *pl)
{
    double radius = pbrt_get_float(pl, "radius", 1.0);
    double phimax = pbrt_get_float(pl, "phimax", 360.0);
    if (!(radius > 0))
        return FAIL_TOK(P, t, "%s: expected a positive radius, found %g", type, radius);
    if (!(phimax > 0 && phimax <= 360))
        return FAIL_TOK(P, t, "%s: expected phimax in (0, 360], found %g", type, phimax);
    unsigned flags = P->gs.reverse ? RAYES_QUADRIC_REVERSE : 0;
    float qp[7];
    size_t n;
    RayesQuadric q;
    double height = 0;
    if (strcmp(type, "sphere") == 0) {
        double zmin = pbrt_get_float(pl, "zmin", -radius),
               zmax = pbrt_get_float(pl, "zmax", radius);
        zmin = zmin < -radius ? -radius : zmin > radius ? radius : zmin;
        zmax = zmax < -radius ? -radius : zmax > radius ? radius : zmax;
        if (!(zmin < zmax))
            return FAIL_TOK(P, t, "sphere: expected zmin < zmax");
        q = RAYES_QUADRIC_SPHERE;
        qp[0] = (float)radius, qp[1] = (float)zmin, qp[2] = (float)zmax, qp[3] = (float)phimax;
        n = 4;
    } else if (strcmp(type, "cylinder") == 0) {
        double zmin = pbrt_get_float(pl, "zmin", -1), zmax = pbrt_get_float(pl, "zmax", 1);
        if (!(zmin != zmax))
            return FAIL_TOK(P, t, "cylinder: expected zmin != zmax");
        q = RAYES_QUADRIC_CYLINDER;
        qp[0] = (float)radius, qp[1] = (float)zmin, qp[2] = (float)zmax, qp[3] = (float)phimax;
        n = 4;
    } else {
        height = pbrt_get_float(pl, "height", 0.0);
        double inner = pbrt_get_float(pl, "innerradius", 0.0);
        if (inner > 0 && inner < radius) {
            /* an annulus: RenderMan's hyperboloid of the line from the rim
             * in to the inner radius, parameterised (and facing) as the
             * disk is */
            q = RAYES_QUADRIC_HYPERBOLOID;
            const float line[7] = {(float)radius, 0, (float)height, (float)inner, 0, (float)height,
                                   (float)phimax};
            memcpy(qp, line, sizeof line);
            n = 7;
        } else {
            if (inner > 0)
                pbrt_warn_at(P, t->line, t->col, "disk innerradius",
                             "disk: \"innerradius\" is not below the radius; the disk is whole");
            q = RAYES_QUADRIC_DISK;
            qp[0] = (float)height, qp[1] = (float)radius, qp[2] = (float)phimax;
            n = 3;
        }
    }
    int whole = phimax >= 360 &&
                (q == RAYES_QUADRIC_DISK || (q == RAYES_QUADRIC_SPHERE && qp[1] <= -qp[0] &&
                                             qp[2] >= qp[0] && !P->gs.reverse));
    if (!P->gs.area.on || P->recording || (!whole && !P->sink->area_light_quadric)) {
        if (P->gs.area.on)
            pbrt_warn_at(P, t->line, t->col,
                         P->recording ? "instanced area light" : "quadric light",
                         "%s: this emitter is not supported (%s); the shape does not emit", type,
                         P->recording ? "inside ObjectBegin" : "the scene takes no quadric lights");
        return pbrt_emit_quadric(P, t, q, qp, n, flags);
    }
    pbrt_grow_quadric(P, q, qp); /* emitters count in the world's bound too */
    double sweep = phimax / 360.0, area; /* object space, then scaled as the transform does */
    if (q == RAYES_QUADRIC_SPHERE || q == RAYES_QUADRIC_CYLINDER)
        area = 2 * PI * radius * fabs((double)qp[2] - qp[1]) * sweep;
    else if (q == RAYES_QUADRIC_HYPERBOLOID) /* the annulus */
        area = PI * (radius * radius - (double)qp[3] * qp[3]) * sweep;
    else
        area = PI * radius * radius * sweep;
    pbrt_area_power(P, 1, area * pow(fabs(pbrt_mat_det3(P->gs.ctm)), 2.0 / 3.0));
    if (!whole) {
        /* a cylinder, a partial sphere or disk, an annulus, an inward
         * sphere: a mesh light of the quadric, facing as pbrt's normal does
         * (a normal transformed stays on its side whatever the handedness,
         * where rayes's front follows the transformed surface) */
        float m[16];
        if (!pbrt_mat_finite(P->gs.ctm))
            return FAIL_TOK(P, t, "the current transform is not finite");
        pbrt_mat_to_float(P->gs.ctm, m);
        if (swaps_handedness(P->gs.ctm))
            flags ^= RAYES_QUADRIC_REVERSE;
        RayesError e = P->sink->set_transform(P->sink->target, m);
        if (e == RAYES_OK)
            e = P->sink->area_light_quadric(P->sink->target, q, qp, n, flags, P->gs.area.L,
                                            P->gs.area.twosided);
        return e == RAYES_OK ? 0 : pbrt_sink_failed(P, t, e);
    }
    if (q == RAYES_QUADRIC_SPHERE)
        return quadric_light(P, t, "sphere", (float)radius, P->gs.ctm);
    double m[16], tr[16], flip[16];
    pbrt_mat_identity(tr);
    tr[11] = height;
    pbrt_mat_mul(P->gs.ctm, tr, m);
    pbrt_mat_identity(flip);
    flip[5] = flip[10] = -1; /* 180 degrees about x: emits toward -z */
    for (int side = 0; side < 1 + P->gs.area.twosided; side++) {
        double ms[16];
        if (P->gs.reverse ^ side)
            pbrt_mat_mul(m, flip, ms);
        else
            memcpy(ms, m, sizeof ms);
        if (quadric_light(P, t, "disk", (float)radius, ms) != 0)
            return -1;
    }
    return 0;
}

/* ------------------------------------------------------------------ curve */

/* pbrt-v4's curve: one curve of Bezier or B-spline segments of degree 2
 * or 3, sent as one cubic Bezier curve (quadratic segments raised to
 * cubic, B-spline ones turned Bezier), its width from width0 to width1
 * along the whole curve (varying), ribbons' normals (one per segment end)
 * as varying N. "cylinder" is a round tube, "flat" a ribbon facing each
 * ray. */
static int shape_curve(Parser *P, const Token *t, ParamList *pl)
{
    Param *pp = pbrt_find(pl, "P"), *np = pbrt_find(pl, "N");
    const char *basis = pbrt_get_string(pl, "basis", "bezier");
    const char *type = pbrt_get_string(pl, "type", "flat");
    double degree_value = pbrt_get_float(pl, "degree", 3);
    int degree = degree_value == 2.0 ? 2 : degree_value == 3.0 ? 3 : 0;
    double width = pbrt_get_float(pl, "width", 1.0);
    double w0 = pbrt_get_float(pl, "width0", width), w1 = pbrt_get_float(pl, "width1", width);
    (void)pbrt_find(pl, "splitdepth"); /* pbrt's refinement: diced like everything else */
    int bspline = strcmp(basis, "bspline") == 0, ribbon = strcmp(type, "ribbon") == 0;
    if (!bspline && strcmp(basis, "bezier") != 0)
        return FAIL_TOK(P, t, "curve: \"basis\" is \"%.40s\"; expected \"bezier\" or \"bspline\"",
                        basis);
    if (degree == 0)
        return FAIL_TOK(P, t, "curve: \"degree\" is %g; expected 2 or 3", degree_value);
    if (!ribbon && strcmp(type, "flat") != 0 && strcmp(type, "cylinder") != 0)
        return FAIL_TOK(P, t, "curve: \"type\" is \"%.40s\"; expected flat, cylinder or ribbon",
                        type);
    size_t n_cp = pp && pp->n_num % 3 == 0 ? pp->n_num / 3 : 0;
    size_t segs = bspline ? (n_cp > (size_t)degree ? n_cp - (size_t)degree : 0)
                          : (n_cp > 1 && (n_cp - 1) % (size_t)degree == 0 ? (n_cp - 1) / (size_t)degree
                                                                          : 0);
    if (segs == 0 || segs > (1u << 20))
        return FAIL_TOK(P, t, "curve: \"point3 P\" has %zu points, which make no whole %s segments "
                              "of degree %d",
                        n_cp, basis, degree);
    if (!(w0 >= 0 && w1 >= 0 && w0 < 1e30 && w1 < 1e30))
        return FAIL_TOK(P, t, "curve: widths must be finite and >= 0");
    if (ribbon && (!np || np->n_num != 3 * (segs + 1)))
        return FAIL_TOK(P, t, "curve: a ribbon needs \"normal N\" with %zu normals (one per "
                              "segment end)",
                        segs + 1);
    if (P->gs.area.on)
        pbrt_warn_at(P, t->line, t->col, "curve area",
                     "curve: area lights are quads in rayes; the curve does not emit");
    float *in = points_of(P, t, pp), *N = ribbon ? points_of(P, t, np) : NULL;
    float *cp = malloc((3 * segs + 1) * 3 * sizeof *cp), *w = malloc((segs + 1) * sizeof *w);
    int r = -1;
    if (!in || (ribbon && !N) || !cp || !w) {
        FAIL_TOK(P, t, "out of memory");
        goto done;
    }
    for (size_t k = 0; k < segs; k++) {
        const float *g = in + 3 * (bspline ? k : k * (size_t)degree);
        float b[4][3]; /* the segment's cubic Bezier points */
        for (int c = 0; c < 3; c++) {
            float p0 = g[c], p1 = g[3 + c], p2 = g[6 + c], p3 = degree == 3 ? g[9 + c] : 0.0f;
            if (degree == 3 && bspline) {
                b[0][c] = (p0 + 4 * p1 + p2) / 6, b[1][c] = (2 * p1 + p2) / 3;
                b[2][c] = (p1 + 2 * p2) / 3, b[3][c] = (p1 + 4 * p2 + p3) / 6;
            } else if (degree == 3) {
                b[0][c] = p0, b[1][c] = p1, b[2][c] = p2, b[3][c] = p3;
            } else { /* quadratic (B-spline made Bezier first), raised to cubic */
                float q0 = bspline ? 0.5f * (p0 + p1) : p0, q2 = bspline ? 0.5f * (p1 + p2) : p2;
                b[0][c] = q0, b[1][c] = q0 + 2.0f / 3 * (p1 - q0);
                b[2][c] = q2 + 2.0f / 3 * (p1 - q2), b[3][c] = q2;
            }
        }
        memcpy(cp + 9 * k, b, (k + 1 == segs ? 12 : 9) * sizeof(float));
        w[k] = (float)(w0 + (w1 - w0) * (double)k / (double)segs);
    }
    w[segs] = (float)w1;
    int n_verts = (int)(3 * segs + 1);
    RayesCurves c = {.degree = 3, .step = 3, .n_curves = 1, .n_verts = &n_verts, .P = cp,
                     .shape = strcmp(type, "cylinder") == 0 ? RAYES_CURVE_ROUND : RAYES_CURVE_FLAT};
    memcpy(c.basis, rayes_basis_bezier, sizeof c.basis);
    RayesPrimvar pv[2] = {{"width", RAYES_PRIMVAR_VARYING, w, segs + 1},
                          {"N", RAYES_PRIMVAR_VARYING, N, segs + 1}};
    r = pbrt_emit_curves(P, t, &c, pv, ribbon ? 2 : 1);
done:
    free(in);
    free(N);
    free(cp);
    free(w);
    return r;
}

/* ------------------------------------------------------------ directives */

/* pbrt-v4's "alpha" of a shape (a float, or a float texture; 0 is a
 * cut-out) as rayes' opacity: the current material with "Os" added, in
 * *out. pbrt cuts out stochastically where alpha is fractional; opacity is
 * the same in expectation. Returns 1 (out set), 0 (no alpha, or 1) or -1. */
static int shape_alpha(Parser *P, const Token *t, ParamList *pl, Material *out)
{
    Param *p = pbrt_find(pl, "alpha");
    (void)pbrt_find(pl, "shadowalpha"); /* pbrt-v3's, for shadows: alpha already cuts them */
    const Texture *tex = NULL;
    float a[3];
    static const float one[3] = {1, 1, 1};
    int k = p ? pbrt_get_color(P, pl, "alpha", one, a, &tex) : 0;
    if (k <= 0)
        return k;
    if (p->type != PT_FLOAT && p->type != PT_TEXTURE)
        return pbrt_fail_at(P, p->line, p->col,
                            "Shape: \"alpha\" must be a float or a float texture, found %s",
                            p->type_name);
    if (k == 1 && a[0] >= 1.0f)
        return 0;
    *out = P->gs.material;
    if (out->n >= MAT_MAX_PARAMS)
        return FAIL_TOK(P, t, "Shape: \"alpha\": the material has too many parameters");
    int i = out->n++;
    memset(&out->p[i], 0, sizeof out->p[i]);
    snprintf(out->p[i].name, sizeof out->p[i].name, "Os");
    out->p[i].type = k == 2 ? RAYES_PARAM_PATTERN : RAYES_PARAM_COLOR;
    for (int c = 0; c < 3; c++)
        out->p[i].v[c] = k == 2 ? 1.0f : fminf(fmaxf(a[0], 0.0f), 1.0f);
    out->p[i].tex = k == 2 ? (size_t)(tex - P->textures) : 0;
    return 1;
}

static int shape_of_type(Parser *P, const Token *t, const char *type, ParamList *pl)
{
    if (strcmp(type, "trianglemesh") == 0)
        return shape_trianglemesh(P, t, pl);
    if (strcmp(type, "bilinearmesh") == 0)
        return shape_bilinearmesh(P, t, pl);
    if (strcmp(type, "loopsubdiv") == 0)
        return shape_loopsubdiv(P, t, pl);
    if (strcmp(type, "plymesh") == 0)
        return shape_plymesh(P, t, pl);
    if (strcmp(type, "curve") == 0)
        return shape_curve(P, t, pl);
    if (strcmp(type, "heightfield") == 0)
        return shape_heightfield(P, t, pl);
    if (strcmp(type, "cone") == 0 || strcmp(type, "paraboloid") == 0 ||
        strcmp(type, "hyperboloid") == 0)
        return shape_v3_quadric(P, t, type, pl);
    if (strcmp(type, "sphere") == 0 || strcmp(type, "disk") == 0 || strcmp(type, "cylinder") == 0)
        return shape_quadric(P, t, type, pl);
    char key[96];
    snprintf(key, sizeof key, "shape %.60s", type);
    pbrt_warn_at(P, t->line, t->col, key, "Shape \"%.40s\" is not supported; skipped", type);
    return 1;
}

/* The Shape (of type and pl) recorded, seen by no ray, into the bound of
 * the medium on each side of it (MediumInterface), turned so that the
 * medium lies behind its normals: a liquid in a glass is bounded by its
 * top (its medium inside) and by the glass's inner wall (its medium
 * outside), neither closed alone (pbrt_media_send sends them). */
static int bound_media(Parser *P, const Token *t, const char *type, ParamList *pl)
{
    if (strcmp(type, "curve") == 0)
        return 0; /* a curve has no sides */
    for (int side = 0; side < 2; side++) {
        Medium *md = pbrt_medium_bounded(P, side);
        if (!md)
            continue;
        Material saved = P->gs.material;
        int reverse = P->gs.reverse, area = P->gs.area.on;
        pbrt_mat_init(&P->gs.material, PBRT_INVISIBLE);
        P->gs.area.on = 0; /* an emitter's copy is only a bound */
        P->gs.reverse ^= side;
        P->recording = &md->bound;
        P->shape_bounds = 1;
        P->have_shape_bound = 0;
        int r = shape_of_type(P, t, type, pl);
        P->recording = NULL;
        P->shape_bounds = 0;
        P->gs.reverse = reverse;
        P->gs.area.on = area;
        P->gs.material = saved;
        if (r < 0)
            return -1;
        pbrt_medium_grow(P, md, t);
    }
    return 0;
}

/* At the start of a Shape whose NamedMaterial is not defined yet: deferred
 * to the file's end (its arguments skipped; 1), or an error inside
 * ObjectBegin (-1); 0 when it is read now. */
static int defer_shape(Parser *P, const Token *t)
{
    if (!P->gs.pending[0] || P->rereading)
        return 0;
    if (P->recording) /* an object's shapes are replayed by instances as they come */
        return pbrt_undefined_material(P, &P->gs, " before an ObjectBegin's shapes");
    if (!pbrt_defer(P, &P->shapes, P->lx, t))
        return -1;
    char type[64];
    ParamList pl = {0};
    int r = pbrt_name_and_params(P, type, sizeof type, "a shape type", &pl, NULL);
    pbrt_params_free(&pl);
    return r ? -1 : 1;
}

int pbrt_deferred_shapes(Parser *P)
{
    for (size_t i = 0; i < P->shapes.n; i++) {
        GState gs = P->shapes.d[i].gs;
        int r;
        const Material *m = pbrt_named_material(P, gs.pending, &r);
        if (r)
            return -1;
        if (!m)
            return pbrt_undefined_material(P, &gs, "");
        gs.material = *m;
        gs.pending[0] = '\0';
        if (pbrt_reread(P, &P->shapes.d[i], &gs, pbrt_d_shape) != 0)
            return -1;
    }
    return 0;
}

int pbrt_d_shape(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    int r = pbrt_need_world(P, t, 1);
    if (!r && (r = defer_shape(P, t)) != 0)
        return r > 0 ? 0 : -1;
    if (!r)
        r = pbrt_name_and_params(P, type, sizeof type, "a shape type", &pl, NULL);
    if (r) {
        pbrt_params_free(&pl);
        return -1;
    }
    P->have_shape_bound = 0;
    P->shape_bounds = 0;
    P->shape_hidden = 0;
    Material saved = P->gs.material, with_alpha;
    r = shape_alpha(P, t, &pl, &with_alpha);
    if (r == 1)
        P->gs.material = with_alpha; /* for this shape only */
    if (r >= 0)
        r = shape_of_type(P, t, type, &pl);
    P->gs.material = saved;
    if (r == 1) { /* skipped */
        pbrt_params_free(&pl);
        return 0;
    }
    if (!r)
        pbrt_warn_unused(P, &pl, "Shape", type);
    if (!r)
        r = pbrt_medium_shape(P, t);
    if (!r)
        r = bound_media(P, t, type, &pl);
    pbrt_params_free(&pl);
    return r;
}
