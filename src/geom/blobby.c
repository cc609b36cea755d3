/*
 * geom/blobby.c — blobby implicit surfaces: the program, its field and an
 * interval bound of it, and the surface nets that make it polygons
 * (geom/blobby.h).
 */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom/blobby.h"

enum { OP_ADD, OP_MUL, OP_MAX, OP_MIN, OP_SUB, OP_DIV, OP_NEG, OP_IDENTITY };
enum {
    LEAF_CONSTANT = 1000,
    LEAF_ELLIPSOID = 1001,
    LEAF_SEGMENT = 1002,
    LEAF_PLANE = 1003,
    LEAF_PLUGIN = 1004,
    LEAF_AIR_DBO = 9000
};

#define BRICK 8      /* cubes per side of the lattice blocks visited whole */
#define MAX_DEPTH 96 /* octree levels, at most (each halves one side) */
#define CREASE_COS                                                                                 \
    0.82f /* a cube whose crossings' normals differ by more (35 degrees)                           \
             holds a crease: its quads take the normals of their sides */

/* A primitive field. */
typedef struct Leaf {
    int kind;              /* LEAF_* */
    float value;           /* a constant's value */
    Mat4 blob_from_object; /* ellipsoids and segments */
    Vec3 a, b;             /* a segment's ends, in blob space */
    float inv_radius;      /* 1 / a segment's radius; 1 for an ellipsoid */
    float stretch;         /* blob-space length per object-space length, at most (times
                              inv_radius): the Frobenius norm of the linear part */
    float radius;          /* a lone leaf's surface's smallest object-space radius */
    float area;            /* a lone leaf's surface's object-space area, at most */
    Bounds3 bound;         /* object-space bound of where the field is not 0 */
} Leaf;

typedef struct Instr {
    int op;   /* OP_*, or a LEAF_* kind */
    int leaf; /* leaves: the index in Blobby.leaves */
    int n_args;
    size_t first; /* operands: args[first .. first + n_args), earlier instructions */
} Instr;

struct Blobby {
    Instr *instr;
    size_t n_instr;
    int *args;
    size_t n_args;
    Leaf *leaves;
    size_t n_leaves, n_unsupported;
};

static int failf(char *msg, size_t n, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int failf(char *msg, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (msg && n)
        vsnprintf(msg, n, fmt, ap);
    va_end(ap);
    return -1;
}

/* ----------------------------------------------------------- the leaves */

/* (1 - r^2)^3 inside the unit ball, 0 outside. */
static inline float bump(float r2)
{
    float t = 1.0f - r2;
    return r2 < 1.0f ? t * t * t : 0.0f;
}

/* The largest singular value of m's linear part (power iteration on
 * M^T M). */
static float largest_stretch(const Mat4 *m)
{
    Vec3 v = v3_normalize(v3(0.577f, 0.591f, 0.563f));
    float s = 0.0f;
    for (int it = 0; it < 32; it++) {
        Vec3 w = mat4_vector(m, v);
        /* M^T w */
        Vec3 u = v3(m->m[0][0] * w.x + m->m[1][0] * w.y + m->m[2][0] * w.z,
                    m->m[0][1] * w.x + m->m[1][1] * w.y + m->m[2][1] * w.z,
                    m->m[0][2] * w.x + m->m[1][2] * w.y + m->m[2][2] * w.z);
        float len = v3_length(u);
        if (!(len > 0.0f))
            break;
        s = sqrtf(len);
        v = v3_scale(u, 1.0f / len);
    }
    return s;
}

/* A blob's matrix from RiBlobby's 16 floats (row vectors); 0 if it is not
 * affine or not invertible. */
static int blob_matrix(const float *f, Mat4 *object_from_blob, Mat4 *blob_from_object)
{
    if (f[3] != 0.0f || f[7] != 0.0f || f[11] != 0.0f || f[15] == 0.0f)
        return 0;
    for (int i = 0; i < 16; i++)
        if (!isfinite(f[i]))
            return 0;
    Mat4 m;
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            m.m[r][c] = f[4 * c + r] / f[15];
    *object_from_blob = m;
    return mat4_invert(m, blob_from_object);
}

/* The radius at which a lone leaf's field reaches the threshold, in its
 * unit sphere: sqrt(1 - T^(1/3)). */
static float surface_radius(void)
{
    return sqrtf(1.0f - cbrtf(BLOBBY_THRESHOLD));
}

static int make_leaf(Leaf *l, int kind, const float *f, char *msg, size_t n_msg, size_t at)
{
    memset(l, 0, sizeof *l);
    l->kind = kind;
    l->bound = bounds_empty();
    if (kind == LEAF_CONSTANT) {
        l->value = isfinite(f[0]) ? f[0] : 0.0f;
        return 0;
    }
    if (kind != LEAF_ELLIPSOID && kind != LEAF_SEGMENT)
        return 0;
    const float *mf = kind == LEAF_SEGMENT ? f + 7 : f;
    Mat4 ob;
    if (!blob_matrix(mf, &ob, &l->blob_from_object))
        return failf(msg, n_msg,
                     "instruction %zu: the blob's matrix is not an invertible affine transform",
                     at);
    float radius = 1.0f;
    Vec3 lo = v3(-1, -1, -1), hi = v3(1, 1, 1);
    if (kind == LEAF_SEGMENT) {
        radius = f[6];
        l->a = v3_load(f), l->b = v3_load(f + 3);
        if (!(radius > 0.0f) || !isfinite(radius) || !isfinite(l->a.x + l->a.y + l->a.z) ||
            !isfinite(l->b.x + l->b.y + l->b.z))
            return failf(msg, n_msg,
                         "instruction %zu: a segment needs finite ends and a "
                         "positive radius",
                         at);
        Vec3 r = v3(radius, radius, radius);
        lo = v3_sub(v3_min(l->a, l->b), r), hi = v3_add(v3_max(l->a, l->b), r);
    }
    l->inv_radius = 1.0f / radius;
    for (int c = 0; c < 8; c++) {
        Vec3 p = v3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
        l->bound = bounds_add(l->bound, mat4_point(&ob, p));
    }
    float frob = 0.0f;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            frob += l->blob_from_object.m[r][c] * l->blob_from_object.m[r][c];
    l->stretch = sqrtf(frob) * l->inv_radius;
    /* A long segment's tube: (1 - d^2)^(7/2) = T. */
    float r_t = kind == LEAF_SEGMENT ? sqrtf(1.0f - powf(BLOBBY_THRESHOLD, 2.0f / 7.0f))
                                     : surface_radius();
    float s = largest_stretch(&l->blob_from_object) * l->inv_radius;
    l->radius = s > 0.0f ? r_t / s : 0.0f;
    float reach = r_t * radius * largest_stretch(&ob);
    float length = v3_length(mat4_vector(&ob, v3_sub(l->b, l->a)));
    l->area = 4.0f * (float)M_PI * reach * reach + 2.0f * (float)M_PI * reach * length;
    return 0;
}

/* The bump's integral along a line, in units of the radius: with
 * a = 1 - d^2 (d the distance to the line), the antiderivative of
 * (a - u^2)^3 in u, and its derivative in a. */
static inline double conv_g(double a, double u)
{
    double u2 = u * u;
    return u * (a * a * a - a * a * u2 + 0.6 * a * u2 * u2 - u2 * u2 * u2 / 7.0);
}
static inline double conv_ga(double a, double u)
{
    double u2 = u * u;
    return u * (3.0 * a * a - 2.0 * a * u2 + 0.6 * u2 * u2);
}

/* A segment's field at blob-space q: the bump convolved along the segment,
 * scaled so that a long segment's axis has 1 (35/32 is 1 over the bump's
 * integral across the line); its gradient in blob space to *dq when dq is
 * not NULL. A chain of segments thus sums to a smooth tube. */
static float segment_field(const Leaf *l, Vec3 q, Vec3 *dq)
{
    const double k = 35.0 / 32.0;
    double ir = l->inv_radius;
    Vec3 ab = v3_sub(l->b, l->a), aq = v3_sub(q, l->a);
    double len = v3_length(ab);
    if (dq)
        *dq = v3(0, 0, 0);
    if (!(len * ir > 1e-6)) { /* a point: the bump of its distance */
        double r2 = v3_dot(aq, aq) * ir * ir;
        if (!(r2 < 1.0))
            return 0.0f;
        double t = 1.0 - r2;
        if (dq)
            *dq = v3_scale(aq, (float)(-6.0 * t * t * ir * ir));
        return (float)(t * t * t);
    }
    Vec3 e = v3_scale(ab, (float)(1.0 / len));
    double t = v3_dot(aq, e);
    Vec3 perp = v3_madd(aq, e, (float)-t);
    double a = 1.0 - v3_dot(perp, perp) * ir * ir;
    if (!(a > 0.0))
        return 0.0f;
    double w = sqrt(a), u0 = -t * ir, u1 = (len - t) * ir;
    double lo = u0 > -w ? u0 : -w, hi = u1 < w ? u1 : w;
    if (!(lo < hi))
        return 0.0f;
    double f = k * (conv_g(a, hi) - conv_g(a, lo));
    if (dq) {
        /* Through a (the distance to the line), and through an end that is
         * the segment's own (a clamped one has a zero bump). */
        double da = k * (conv_ga(a, hi) - conv_ga(a, lo)) * -2.0 * ir * ir;
        Vec3 g = v3_scale(perp, (float)da);
        double dt = 0.0;
        if (hi == u1) {
            double b = a - u1 * u1;
            dt += k * b * b * b * -ir;
        }
        if (lo == u0) {
            double b = a - u0 * u0;
            dt -= k * b * b * b * -ir;
        }
        *dq = v3_madd(g, e, (float)dt);
    }
    return (float)f;
}

/* A leaf's field at p, and its gradient when g is not NULL. */
static float leaf_field(const Leaf *l, Vec3 p, Vec3 *g)
{
    if (g)
        *g = v3(0, 0, 0);
    if (l->kind == LEAF_CONSTANT)
        return l->value;
    if (l->kind != LEAF_ELLIPSOID && l->kind != LEAF_SEGMENT)
        return 0.0f;
    Vec3 q = mat4_point(&l->blob_from_object, p), v;
    float f;
    if (l->kind == LEAF_SEGMENT) {
        f = segment_field(l, q, g ? &v : NULL);
    } else {
        float r2 = v3_dot(q, q);
        if (!(r2 < 1.0f))
            return 0.0f;
        float t = 1.0f - r2;
        f = t * t * t;
        v = v3_scale(q, -6.0f * t * t); /* dF/dq */
    }
    if (g) { /* through the linear part, transposed */
        const float(*m)[4] = l->blob_from_object.m;
        *g = v3(m[0][0] * v.x + m[1][0] * v.y + m[2][0] * v.z,
                m[0][1] * v.x + m[1][1] * v.y + m[2][1] * v.z,
                m[0][2] * v.x + m[1][2] * v.y + m[2][2] * v.z);
    }
    return f;
}

/* The range of a leaf's field over the ball of centre c and radius rho.
 * An ellipsoid's bump falls with the distance; a segment's field is at
 * most (1 - d^2)^(7/2) at distance d (in radii) from the segment, at
 * least 0, and changes by at most 2.2 per radius. */
static void leaf_range(const Leaf *l, Vec3 c, float rho, float *lo, float *hi)
{
    if (l->kind == LEAF_CONSTANT) {
        *lo = *hi = l->value;
        return;
    }
    if (l->kind != LEAF_ELLIPSOID && l->kind != LEAF_SEGMENT) {
        *lo = *hi = 0.0f;
        return;
    }
    Vec3 q = mat4_point(&l->blob_from_object, c);
    float s = rho * l->stretch;
    if (l->kind == LEAF_ELLIPSOID) {
        float r = v3_length(q);
        float rlo = fmaxf(r - s, 0.0f), rhi = r + s;
        *lo = bump(rhi * rhi);
        *hi = bump(rlo * rlo);
        return;
    }
    Vec3 ab = v3_sub(l->b, l->a);
    float len2 = v3_dot(ab, ab);
    float t = len2 > 0.0f ? fminf(fmaxf(v3_dot(v3_sub(q, l->a), ab) / len2, 0.0f), 1.0f) : 0.0f;
    float d = v3_length(v3_sub(q, v3_madd(l->a, ab, t))) * l->inv_radius;
    float dlo = fmaxf(d - s, 0.0f);
    float top = dlo < 1.0f ? powf(1.0f - dlo * dlo, 3.5f) : 0.0f;
    float f = segment_field(l, q, NULL);
    *lo = fmaxf(f - 2.2f * s, 0.0f);
    *hi = fminf(top, f + 2.2f * s);
    if (*hi < *lo)
        *hi = *lo;
}

/* ----------------------------------------------------------- compiling */

void blobby_free(Blobby *b)
{
    if (!b)
        return;
    free(b->instr);
    free(b->args);
    free(b->leaves);
    free(b);
}

Blobby *blobby_compile(const int *code, size_t n_code, const float *floats, size_t n_floats,
                       size_t n_strings, char *msg, size_t n_msg)
{
    Blobby *b = calloc(1, sizeof *b);
    if (b) {
        b->instr = malloc((n_code + 1) * sizeof *b->instr);
        b->args = malloc((n_code + 1) * sizeof *b->args);
        b->leaves = malloc((n_code + 1) * sizeof *b->leaves);
    }
    if (!b || !b->instr || !b->args || !b->leaves) {
        blobby_free(b);
        failf(msg, n_msg, "out of memory");
        return NULL;
    }
    int bad = 0;
    size_t c = 0;
    while (c < n_code && !bad) {
        size_t at = b->n_instr;
        int op = code[c++];
        Instr *in = &b->instr[b->n_instr];
        *in = (Instr){op, -1, 0, b->n_args};
        size_t rest = n_code - c;
        if (op >= LEAF_CONSTANT && op <= LEAF_PLUGIN) {
            static const int n_ops[] = {1, 1, 1, 2, 5};
            static const size_t n_f[] = {1, 16, 23, 4};
            int k = op - LEAF_CONSTANT;
            if (rest < (size_t)n_ops[k]) {
                bad = failf(msg, n_msg, "instruction %zu (opcode %d): expected %d operands", at, op,
                            n_ops[k]);
                break;
            }
            const int *o = code + c;
            c += (size_t)n_ops[k];
            long fi = op == LEAF_PLANE ? o[1] : op == LEAF_PLUGIN ? o[2] : o[0];
            long nf = op == LEAF_PLUGIN ? o[1] : (long)n_f[k];
            int strings_ok = op == LEAF_PLANE ? o[0] >= 0 && (size_t)o[0] < n_strings
                             : op == LEAF_PLUGIN
                                 ? o[0] >= 0 && (size_t)o[0] < n_strings && o[3] >= 0 &&
                                       o[4] >= 0 && (size_t)o[4] + (size_t)o[3] <= n_strings
                                 : 1;
            if (!strings_ok) {
                bad = failf(msg, n_msg,
                            "instruction %zu (opcode %d): a string index is past "
                            "the %zu strings",
                            at, op, n_strings);
                break;
            }
            if (fi < 0 || nf < 0 || (size_t)fi + (size_t)nf > n_floats) {
                bad = failf(msg, n_msg,
                            "instruction %zu (opcode %d): needs floats %ld to %ld; %zu are given",
                            at, op, fi, fi + nf - 1, n_floats);
                break;
            }
            in->leaf = (int)b->n_leaves;
            const float *f = n_floats ? floats + fi : NULL;
            if (make_leaf(&b->leaves[b->n_leaves], op, f, msg, n_msg, at) != 0) {
                bad = 1;
                break;
            }
            b->n_unsupported += op == LEAF_PLANE || op == LEAF_PLUGIN;
            b->n_leaves++;
        } else if (op >= OP_ADD && op <= OP_IDENTITY) {
            long n = op <= OP_MIN ? (rest ? code[c++] : -1) : op <= OP_DIV ? 2 : 1;
            rest = n_code - c;
            if (n < 1 || (size_t)n > rest) {
                bad = failf(msg, n_msg, "instruction %zu (opcode %d): expected %s", at, op,
                            op <= OP_MIN ? "a count of at least 1 and that many operands"
                                         : "its operands");
                break;
            }
            for (long k = 0; k < n; k++) {
                int a = code[c++];
                if (a < 0 || (size_t)a >= at) {
                    bad = failf(msg, n_msg,
                                "instruction %zu (opcode %d): operand %d is not an earlier "
                                "instruction",
                                at, op, a);
                    break;
                }
                b->args[b->n_args++] = a;
            }
            in->n_args = (int)n;
        } else if (op == LEAF_AIR_DBO) { /* AIR's plugin blob: a count, then operands */
            if (rest < 1 || code[c] < 0 || (size_t)code[c] > rest - 1) {
                bad = failf(msg, n_msg,
                            "instruction %zu (opcode 9000): expected a count and that many "
                            "operands",
                            at);
                break;
            }
            c += 1 + (size_t)code[c];
            in->leaf = (int)b->n_leaves;
            make_leaf(&b->leaves[b->n_leaves++], op, NULL, msg, n_msg, at);
            b->n_unsupported++;
        } else {
            bad = failf(msg, n_msg,
                        "instruction %zu: unknown opcode %d (expected 0 to 7, 1000 to 1004 or "
                        "9000)",
                        at, op);
            break;
        }
        b->n_instr++;
    }
    if (!bad && b->n_instr == 0)
        bad = failf(msg, n_msg, "the program has no instructions");
    if (bad) {
        blobby_free(b);
        return NULL;
    }
    return b;
}

size_t blobby_leaf_count(const Blobby *b)
{
    return b->n_leaves;
}
size_t blobby_unsupported_count(const Blobby *b)
{
    return b->n_unsupported;
}

/* ------------------------------------------------------------ the field */

/* Instruction i at p from its n operands a (earlier instructions' values
 * in val, gradients in g when g is not NULL): sets val[i] (and g[i]). */
static void step(const Blobby *b, size_t i, const int *a, int n, Vec3 p, float *val, Vec3 *g)
{
    const Instr *in = &b->instr[i];
    float v = 0.0f;
    Vec3 d = v3(0, 0, 0);
    switch (in->op) {
    case OP_ADD:
        for (int k = 0; k < n; k++) {
            v += val[a[k]];
            if (g)
                d = v3_add(d, g[a[k]]);
        }
        break;
    case OP_MUL:
        v = val[a[0]];
        if (g)
            d = g[a[0]];
        for (int k = 1; k < n; k++) {
            if (g)
                d = v3_add(v3_scale(d, val[a[k]]), v3_scale(g[a[k]], v));
            v *= val[a[k]];
        }
        break;
    case OP_MAX:
    case OP_MIN: {
        int best = a[0];
        for (int k = 1; k < n; k++)
            if (in->op == OP_MAX ? val[a[k]] > val[best] : val[a[k]] < val[best])
                best = a[k];
        v = val[best];
        if (g)
            d = g[best];
        break;
    }
    case OP_SUB:
        v = val[a[0]] - val[a[1]];
        if (g)
            d = v3_sub(g[a[0]], g[a[1]]);
        break;
    case OP_DIV: {
        float x = val[a[0]], y = val[a[1]];
        if (y != 0.0f) { /* x / 0 is taken as 0 */
            v = x / y;
            if (g)
                d = v3_scale(v3_sub(v3_scale(g[a[0]], y), v3_scale(g[a[1]], x)), 1.0f / (y * y));
        }
        break;
    }
    case OP_NEG:
        v = -val[a[0]];
        if (g)
            d = v3_neg(g[a[0]]);
        break;
    case OP_IDENTITY:
        v = val[a[0]];
        if (g)
            d = g[a[0]];
        break;
    default: /* a leaf */
        v = leaf_field(&b->leaves[in->leaf], p, g ? &d : NULL);
        break;
    }
    val[i] = isfinite(v) ? v : 0.0f;
    if (g)
        g[i] = isfinite(d.x + d.y + d.z) ? d : v3(0, 0, 0);
}

/* Runs the whole program at p; val (and g, when not NULL) hold every
 * instruction's value (gradient). Returns the field. */
static float run(const Blobby *b, Vec3 p, float *val, Vec3 *g)
{
    float f = 0.0f;
    for (size_t i = 0; i < b->n_instr; i++) {
        step(b, i, b->args + b->instr[i].first, b->instr[i].n_args, p, val, g);
        f = val[i];
    }
    return f;
}

float blobby_field(const Blobby *b, Vec3 p, Vec3 *grad)
{
    float *val = malloc(b->n_instr * (sizeof *val + (grad ? sizeof(Vec3) : 0)));
    if (!val)
        return 0.0f;
    Vec3 *g = grad ? (Vec3 *)(val + b->n_instr) : NULL;
    float f = run(b, p, val, g);
    if (grad && b->n_instr)
        *grad = g[b->n_instr - 1];
    free(val);
    return f;
}

void blobby_leaf_fields(const Blobby *b, Vec3 p, float *out)
{
    for (size_t i = 0; i < b->n_leaves; i++)
        out[i] = b->leaves[i].kind == LEAF_CONSTANT ? 0.0f : leaf_field(&b->leaves[i], p, NULL);
}

/* The program over ranges: each leaf's [leaf_lo, leaf_hi]; the field's
 * range goes to *lo, *hi. */
static void run_range(const Blobby *b, const float *leaf_lo, const float *leaf_hi, float *lo,
                      float *hi, float *vlo, float *vhi)
{
    for (size_t i = 0; i < b->n_instr; i++) {
        const Instr *in = &b->instr[i];
        const int *a = b->args + in->first;
        float l = 0.0f, h = 0.0f;
        switch (in->op) {
        case OP_ADD:
            for (int k = 0; k < in->n_args; k++)
                l += vlo[a[k]], h += vhi[a[k]];
            break;
        case OP_MUL:
            l = vlo[a[0]], h = vhi[a[0]];
            for (int k = 1; k < in->n_args; k++) {
                float l2 = vlo[a[k]], h2 = vhi[a[k]];
                if ((l == 0.0f && h == 0.0f) || (l2 == 0.0f && h2 == 0.0f)) {
                    l = h = 0.0f;
                    continue;
                }
                float p[4] = {l * l2, l * h2, h * l2, h * h2};
                l = fminf(fminf(p[0], p[1]), fminf(p[2], p[3]));
                h = fmaxf(fmaxf(p[0], p[1]), fmaxf(p[2], p[3]));
            }
            break;
        case OP_MAX:
        case OP_MIN:
            l = vlo[a[0]], h = vhi[a[0]];
            for (int k = 1; k < in->n_args; k++) {
                l = in->op == OP_MAX ? fmaxf(l, vlo[a[k]]) : fminf(l, vlo[a[k]]);
                h = in->op == OP_MAX ? fmaxf(h, vhi[a[k]]) : fminf(h, vhi[a[k]]);
            }
            break;
        case OP_SUB:
            l = vlo[a[0]] - vhi[a[1]], h = vhi[a[0]] - vlo[a[1]];
            break;
        case OP_DIV: {
            float xl = vlo[a[0]], xh = vhi[a[0]], yl = vlo[a[1]], yh = vhi[a[1]];
            if ((xl == 0.0f && xh == 0.0f) || (yl == 0.0f && yh == 0.0f))
                break; /* 0 / y and x / 0 are 0 */
            if (yl > 0.0f || yh < 0.0f) {
                float p[4] = {xl / yl, xl / yh, xh / yl, xh / yh};
                l = fminf(fminf(p[0], p[1]), fminf(p[2], p[3]));
                h = fmaxf(fmaxf(p[0], p[1]), fmaxf(p[2], p[3]));
            } else {
                l = -INFINITY, h = INFINITY;
                if (yl < 0.0f || yh > 0.0f) /* x / 0 = 0 is inside this too */
                    break;
            }
            break;
        }
        case OP_NEG:
            l = -vhi[a[0]], h = -vlo[a[0]];
            break;
        case OP_IDENTITY:
            l = vlo[a[0]], h = vhi[a[0]];
            break;
        default:
            l = leaf_lo[in->leaf], h = leaf_hi[in->leaf];
            break;
        }
        vlo[i] = isnan(l) ? -INFINITY : l;
        vhi[i] = isnan(h) ? INFINITY : h;
    }
    *lo = vlo[b->n_instr - 1];
    *hi = vhi[b->n_instr - 1];
}

/* --------------------------------------------------------- surface nets */

/* The cubes the surface crosses: a hash from lattice cell to vertex. */
typedef struct Nets {
    const Blobby *b;
    Vec3 origin;
    float h;
    int n[3]; /* cubes per axis */
    size_t max_points;
    /* scratch */
    float *val, *vlo, *vhi;   /* n_instr each */
    Vec3 *grad;               /* n_instr */
    float *leaf_lo, *leaf_hi; /* n_leaves each, 0 but where a range is set */
    int *active;              /* MAX_DEPTH lists of n_leaves leaf indices */
    /* the program where a block is (make_live) */
    int *live; /* the instructions not 0 there, in order */
    size_t n_live;
    int *live_first, *live_n; /* per instruction: its operands in live_args */
    int *live_args;           /* n_args */
    /* the vertices */
    float *P, *N;
    uint64_t *cell;      /* each vertex's cube (key) */
    unsigned char *mask; /* each vertex's cube's corners inside (bit x + 2y + 4z) */
    int *side;           /* each vertex's block of 12 normals in side_N, or -1 */
    float *side_N;       /* at a crease, per cube edge (edge_id), the normal of the
                            side of it the edge's quad lies on: 36 floats a block */
    size_t n_side, cap_side;
    size_t n_points, cap_points;
    uint64_t *keys; /* hash: key + 1 (0 empty) */
    int *slot;
    size_t cap_hash;
    int status; /* 0, 1 too many points, -1 out of memory */
} Nets;

static inline uint64_t cell_key(int i, int j, int k)
{
    return ((uint64_t)i << 42) | ((uint64_t)j << 21) | (uint64_t)k;
}

static inline uint64_t hash64(uint64_t x)
{
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33;
    return x;
}

static int find_cell(const Nets *x, int i, int j, int k)
{
    if (i < 0 || j < 0 || k < 0 || !x->cap_hash)
        return -1;
    uint64_t key = cell_key(i, j, k) + 1;
    for (size_t s = hash64(key) & (x->cap_hash - 1);; s = (s + 1) & (x->cap_hash - 1)) {
        if (x->keys[s] == key)
            return x->slot[s];
        if (x->keys[s] == 0)
            return -1;
    }
}

static void hash_put(uint64_t *keys, int *slot, size_t cap, uint64_t key, int v)
{
    size_t s = hash64(key) & (cap - 1);
    while (keys[s] != 0)
        s = (s + 1) & (cap - 1);
    keys[s] = key, slot[s] = v;
}

static int add_vertex(Nets *x, int i, int j, int k, unsigned char mask, const Vec3 *side, Vec3 p,
                      Vec3 n)
{
    if (x->n_points >= x->max_points) {
        x->status = 1;
        return -1;
    }
    if (x->n_points == x->cap_points) {
        size_t cap = x->cap_points ? 2 * x->cap_points : 1024;
        float *P = realloc(x->P, cap * 3 * sizeof *P);
        if (P)
            x->P = P;
        float *N = realloc(x->N, cap * 3 * sizeof *N);
        if (N)
            x->N = N;
        uint64_t *c = realloc(x->cell, cap * sizeof *c);
        if (c)
            x->cell = c;
        unsigned char *m = realloc(x->mask, cap);
        if (m)
            x->mask = m;
        int *cr = realloc(x->side, cap * sizeof *cr);
        if (cr)
            x->side = cr;
        if (!P || !N || !c || !m || !cr) {
            x->status = -1;
            return -1;
        }
        x->cap_points = cap;
    }
    if (2 * (x->n_points + 1) > x->cap_hash) {
        size_t cap = x->cap_hash ? 2 * x->cap_hash : 4096;
        uint64_t *keys = calloc(cap, sizeof *keys);
        int *slot = malloc(cap * sizeof *slot);
        if (!keys || !slot) {
            free(keys);
            free(slot);
            x->status = -1;
            return -1;
        }
        for (size_t s = 0; s < x->cap_hash; s++)
            if (x->keys[s])
                hash_put(keys, slot, cap, x->keys[s], x->slot[s]);
        free(x->keys);
        free(x->slot);
        x->keys = keys, x->slot = slot, x->cap_hash = cap;
    }
    size_t v = x->n_points++;
    v3_store(x->P + 3 * v, p);
    v3_store(x->N + 3 * v, n);
    x->cell[v] = cell_key(i, j, k);
    x->mask[v] = mask;
    x->side[v] = -1;
    if (side) {
        if (x->n_side == x->cap_side) {
            size_t cap = x->cap_side ? 2 * x->cap_side : 256;
            float *f = realloc(x->side_N, cap * 36 * sizeof *f);
            if (!f) {
                x->status = -1;
                return -1;
            }
            x->side_N = f, x->cap_side = cap;
        }
        for (int e = 0; e < 12; e++)
            v3_store(x->side_N + 36 * x->n_side + 3 * (size_t)e, side[e]);
        x->side[v] = (int)x->n_side++;
    }
    hash_put(x->keys, x->slot, x->cap_hash, cell_key(i, j, k) + 1, (int)v);
    return 0;
}

static inline Vec3 lattice_point(const Nets *x, int i, int j, int k)
{
    return v3(x->origin.x + (float)i * x->h, x->origin.y + (float)j * x->h,
              x->origin.z + (float)k * x->h);
}

/* The program over the ball (c, rho), where only the leaves of list
 * (n_list) may reach: the instructions not identically 0 there, each sum
 * without its operands that are; the others' values and gradients set to
 * 0. Adding a 0 is exact, so a lattice point shared by two blocks gets the
 * same field from either. */
static void make_live(Nets *x, const int *list, size_t n_list, Vec3 c, float rho)
{
    const Blobby *b = x->b;
    for (size_t k = 0; k < n_list; k++)
        leaf_range(&b->leaves[list[k]], c, rho, &x->leaf_lo[list[k]], &x->leaf_hi[list[k]]);
    float flo, fhi;
    run_range(b, x->leaf_lo, x->leaf_hi, &flo, &fhi, x->vlo, x->vhi);
    for (size_t k = 0; k < n_list; k++)
        x->leaf_lo[list[k]] = x->leaf_hi[list[k]] = 0.0f;
    size_t na = 0;
    x->n_live = 0;
    for (size_t i = 0; i < b->n_instr; i++) {
        if (x->vlo[i] == 0.0f && x->vhi[i] == 0.0f) {
            x->val[i] = 0.0f;
            x->grad[i] = v3(0, 0, 0);
            continue;
        }
        const Instr *in = &b->instr[i];
        x->live[x->n_live++] = (int)i;
        x->live_first[i] = (int)na;
        int n = 0;
        for (int k = 0; k < in->n_args; k++) {
            int a = b->args[in->first + (size_t)k];
            if (in->op == OP_ADD && x->vlo[a] == 0.0f && x->vhi[a] == 0.0f)
                continue;
            x->live_args[na++] = a;
            n++;
        }
        x->live_n[i] = n;
    }
}

/* The field at p by the live program (and its gradient when g is not
 * NULL). */
static float run_live(Nets *x, Vec3 p, Vec3 *g)
{
    const Blobby *b = x->b;
    for (size_t k = 0; k < x->n_live; k++) {
        int i = x->live[k];
        step(b, (size_t)i, x->live_args + x->live_first[i], x->live_n[i], p, x->val,
             g ? x->grad : NULL);
    }
    if (g)
        *g = x->grad[b->n_instr - 1];
    return x->val[b->n_instr - 1];
}

/* The index (0 to 11) of a cube's edge from corner c along axis a (bit a
 * of c clear): a times 4 plus its offsets along the two other axes. */
static inline int edge_id(int c, int a)
{
    int b = (a + 1) % 3, d = (a + 2) % 3;
    return 4 * a + ((c >> b) & 1) + 2 * ((c >> d) & 1);
}

/* Solves the 3 x 3 system m x = r (Cramer's rule); 0 if singular. */
static int solve3(const double m[3][3], const double r[3], double x[3])
{
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                 m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (!(fabs(det) > 1e-12))
        return 0;
    for (int c = 0; c < 3; c++) {
        double a[3][3];
        memcpy(a, m, sizeof a);
        for (int k = 0; k < 3; k++)
            a[k][c] = r[k];
        x[c] = (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])) /
               det;
    }
    return 1;
}

/* The field and its gradient at p (the block's leaves). */
static float field_at(Nets *x, Vec3 p, Vec3 *g)
{
    return run_live(x, p, g);
}

/* The vertex of one cube (v holds its 8 corners' fields): the point
 * nearest to the tangent planes at its edges' crossings (dual contouring's
 * quadric, pulled a little toward their mean), which finds the crease a
 * maximum, minimum or difference makes, then moved onto the surface by
 * Newton steps (kept when they stay within a cube's side). Its normal is
 * the field's falling gradient there. */
static int cube_vertex(Nets *x, Vec3 base, const float v[8], Vec3 *p_out, Vec3 *n_out,
                       Vec3 side[12])
{
    const float T = BLOBBY_THRESHOLD, h = x->h;
    Vec3 pts[12], nrm[12];
    int edge[12];
    int count = 0;
    Vec3 sum = v3(0, 0, 0);
    for (int c = 0; c < 8; c++)
        for (int a = 0; a < 3; a++) {
            int c2 = c | (1 << a);
            if (c2 == c || (v[c] > T) == (v[c2] > T))
                continue;
            float t = (T - v[c]) / (v[c2] - v[c]);
            Vec3 q = v3((float)(c & 1), (float)((c >> 1) & 1), (float)((c >> 2) & 1));
            float *qa = a == 0 ? &q.x : a == 1 ? &q.y : &q.z;
            *qa += t;
            pts[count] = v3_madd(base, q, h);
            edge[count] = edge_id(c, a);
            sum = v3_add(sum, pts[count]);
            Vec3 g;
            field_at(x, pts[count], &g);
            float len = v3_length(g);
            nrm[count++] = len > 0.0f ? v3_scale(g, 1.0f / len) : v3(0, 0, 0);
        }
    Vec3 p0 = v3_scale(sum, 1.0f / (float)count), p = p0;
    float cos_min = 1.0f;
    for (int i = 0; i < count; i++)
        for (int j = i + 1; j < count; j++)
            cos_min = fminf(cos_min, v3_dot(nrm[i], nrm[j]));
    const double lambda = 0.05;
    double m[3][3] = {{lambda, 0, 0}, {0, lambda, 0}, {0, 0, lambda}};
    double r[3] = {0, 0, 0}, sol[3];
    for (int i = 0; i < count; i++) {
        const float n[3] = {nrm[i].x, nrm[i].y, nrm[i].z};
        double b = v3_dot(nrm[i], v3_sub(pts[i], p0)); /* about the mean */
        for (int a = 0; a < 3; a++) {
            for (int c = 0; c < 3; c++)
                m[a][c] += (double)n[a] * n[c];
            r[a] += n[a] * b;
        }
    }
    if (solve3(m, r, sol)) {
        Vec3 q = v3_add(p0, v3((float)sol[0], (float)sol[1], (float)sol[2]));
        if (v3_length(v3_sub(q, p0)) <= h)
            p0 = p = q;
    }
    Vec3 g;
    float f = field_at(x, p, &g);
    for (int it = 0; it < 8 && fabsf(f - T) > 1e-6f; it++) {
        float gg = v3_dot(g, g);
        if (!(gg > 0.0f))
            break;
        Vec3 q = v3_madd(p, g, -(f - T) / gg);
        if (v3_length(v3_sub(q, p0)) > h) { /* a step out of reach: keep the start */
            p = p0;
            f = field_at(x, p, &g);
            break;
        }
        p = q;
        f = field_at(x, p, &g);
    }
    float len = v3_length(g);
    if (!(len > 0.0f)) { /* no gradient: the corners' differences */
        g = v3((v[1] + v[3] + v[5] + v[7]) - (v[0] + v[2] + v[4] + v[6]),
               (v[2] + v[3] + v[6] + v[7]) - (v[0] + v[1] + v[4] + v[5]),
               (v[4] + v[5] + v[6] + v[7]) - (v[0] + v[1] + v[2] + v[3]));
        len = v3_length(g);
    }
    *p_out = p;
    *n_out = len > 0.0f ? v3_scale(g, -1.0f / len) : v3(0, 0, 1);
    if (!(cos_min < CREASE_COS))
        return 0;
    /* A crease: each crossing edge's quad takes the normal halfway to its
     * crossing, on its own side. */
    for (int e = 0; e < 12; e++)
        side[e] = *n_out;
    for (int k = 0; k < count; k++) {
        field_at(x, v3_lerp(p, pts[k], 0.5f), &g);
        len = v3_length(g);
        if (len > 0.0f)
            side[edge[k]] = v3_scale(g, -1.0f / len);
    }
    return 1;
}

/* Every cube of a block (lo to hi, at most BRICK per side) the surface
 * crosses gets its vertex. */
static void brick(Nets *x, const int lo[3], const int hi[3], const int *list, size_t n_list)
{
    const float T = BLOBBY_THRESHOLD, h = x->h;
    int d[3] = {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1};
    float v[(BRICK + 1) * (BRICK + 1) * (BRICK + 1)];
    /* Leaves that reach the block or a cube's side beyond it (Newton steps). */
    Vec3 blo = lattice_point(x, lo[0], lo[1], lo[2]), bhi = lattice_point(x, hi[0], hi[1], hi[2]);
    Vec3 c = v3_scale(v3_add(blo, bhi), 0.5f);
    float rho = 0.5f * v3_length(v3_sub(bhi, blo)) + 2.0f * h;
    make_live(x, list, n_list, c, rho);
    for (int k = 0; k < d[2]; k++)
        for (int j = 0; j < d[1]; j++)
            for (int i = 0; i < d[0]; i++)
                v[(k * d[1] + j) * d[0] + i] =
                    run_live(x, lattice_point(x, lo[0] + i, lo[1] + j, lo[2] + k), NULL);
    for (int k = 0; k + 1 < d[2] && x->status == 0; k++)
        for (int j = 0; j + 1 < d[1] && x->status == 0; j++)
            for (int i = 0; i + 1 < d[0] && x->status == 0; i++) {
                float cv[8];
                unsigned mask = 0;
                for (int q = 0; q < 8; q++) {
                    int ii = i + (q & 1), jj = j + ((q >> 1) & 1), kk = k + ((q >> 2) & 1);
                    cv[q] = v[(kk * d[1] + jj) * d[0] + ii];
                    mask |= (unsigned)(cv[q] > T) << q;
                }
                if (mask == 0 || mask == 255)
                    continue;
                Vec3 p, n, side[12];
                int crease = cube_vertex(x, lattice_point(x, lo[0] + i, lo[1] + j, lo[2] + k), cv,
                                         &p, &n, side);
                add_vertex(x, lo[0] + i, lo[1] + j, lo[2] + k, (unsigned char)mask,
                           crease ? side : NULL, p, n);
            }
}

/* Visits the cubes lo to hi (exclusive) the surface may cross: the field's
 * range over them, from the leaves of list that reach them, must hold the
 * threshold; small enough, a block; else its halves. */
static void descend(Nets *x, const int lo[3], const int hi[3], const int *list, size_t n_list,
                    int depth)
{
    const Blobby *b = x->b;
    if (x->status != 0)
        return;
    Vec3 blo = lattice_point(x, lo[0], lo[1], lo[2]), bhi = lattice_point(x, hi[0], hi[1], hi[2]);
    Vec3 c = v3_scale(v3_add(blo, bhi), 0.5f);
    float rho = 0.5f * v3_length(v3_sub(bhi, blo));
    /* The leaves that reach the cubes or two cubes' sides beyond (where a
     * block's vertices may move to) go on to the halves. */
    int *mine = x->active + (size_t)depth * b->n_leaves;
    size_t n_mine = 0;
    for (size_t k = 0; k < n_list; k++) {
        int l = list[k];
        float near_lo, near_hi;
        leaf_range(&b->leaves[l], c, rho + 2.0f * x->h, &near_lo, &near_hi);
        if (near_hi != 0.0f || near_lo != 0.0f)
            mine[n_mine++] = l;
        leaf_range(&b->leaves[l], c, rho, &x->leaf_lo[l], &x->leaf_hi[l]);
    }
    float flo, fhi;
    run_range(b, x->leaf_lo, x->leaf_hi, &flo, &fhi, x->vlo, x->vhi);
    for (size_t k = 0; k < n_list; k++)
        x->leaf_lo[list[k]] = x->leaf_hi[list[k]] = 0.0f;
    if (!(flo <= BLOBBY_THRESHOLD && fhi >= BLOBBY_THRESHOLD))
        return; /* wholly outside, or wholly inside */
    int axis = 0;
    for (int a = 1; a < 3; a++)
        if (hi[a] - lo[a] > hi[axis] - lo[axis])
            axis = a;
    if (hi[axis] - lo[axis] <= BRICK || depth + 1 >= MAX_DEPTH) {
        brick(x, lo, hi, mine, n_mine);
        return;
    }
    int mid = lo[axis] + (hi[axis] - lo[axis]) / 2;
    int hi1[3] = {hi[0], hi[1], hi[2]}, lo2[3] = {lo[0], lo[1], lo[2]};
    hi1[axis] = mid, lo2[axis] = mid;
    descend(x, lo, hi1, mine, n_mine, depth + 1);
    descend(x, lo2, hi, mine, n_mine, depth + 1);
}

/* The bound of the leaves whose field is bounded (empty if none). */
static Bounds3 leaves_bound(const Blobby *b)
{
    Bounds3 box = bounds_empty();
    for (size_t i = 0; i < b->n_leaves; i++)
        if (b->leaves[i].kind == LEAF_ELLIPSOID || b->leaves[i].kind == LEAF_SEGMENT)
            box = bounds_union(box, b->leaves[i].bound);
    return box;
}

float blobby_default_cell(const Blobby *b)
{
    float r = INFINITY;
    for (size_t i = 0; i < b->n_leaves; i++)
        if ((b->leaves[i].kind == LEAF_ELLIPSOID || b->leaves[i].kind == LEAF_SEGMENT) &&
            b->leaves[i].radius > 0.0f)
            r = fminf(r, b->leaves[i].radius);
    return isfinite(r) ? r / 6.0f : 0.0f;
}

double blobby_estimate_points(const Blobby *b, float cell)
{
    double area = 0.0;
    for (size_t i = 0; i < b->n_leaves; i++)
        area += b->leaves[i].area;
    return cell > 0.0f ? 1.2 * area / ((double)cell * cell) : 0.0;
}

void blobby_mesh_free(BlobbyMesh *m)
{
    free(m->P);
    free(m->N);
    free(m->corner_N);
    free(m->quads);
    memset(m, 0, sizeof *m);
}

/* One quad per lattice edge the surface crosses, from the four cubes
 * around it (each edge taken from the cube it starts at the corner of),
 * with its corners' normals: the point's, or at a crease the one of the
 * quad's side (stored per cube edge: the lattice edge is C0's edge at its
 * corner 0 along the axis, C1's at +b, C2's at +b +c, C3's at +c). */
static int make_quads(Nets *x, BlobbyMesh *out)
{
    static const int offset[4] = {0, 1, 3, 2}; /* C0..C3's edge_id offsets */
    size_t cap = 0, n = 0;
    int *q = NULL;
    float *cn = NULL;
    for (size_t v = 0; v < x->n_points; v++) {
        uint64_t key = x->cell[v];
        int c[3] = {(int)(key >> 42), (int)((key >> 21) & 0x1fffff), (int)(key & 0x1fffff)};
        unsigned mask = x->mask[v];
        for (int a = 0; a < 3; a++) {
            int in0 = mask & 1, in1 = (mask >> (1 << a)) & 1;
            if (in0 == in1)
                continue;
            int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
            int idx[4], ok = 1;
            for (int k = 0; k < 4 && ok; k++) {
                int cell[3] = {c[0], c[1], c[2]};
                cell[b1] -= k == 1 || k == 2;
                cell[b2] -= k == 2 || k == 3;
                ok = (idx[k] = find_cell(x, cell[0], cell[1], cell[2])) >= 0;
            }
            if (!ok)
                continue;
            if (n == cap) {
                cap = cap ? 2 * cap : 1024;
                int *g = realloc(q, cap * 4 * sizeof *g);
                if (g)
                    q = g;
                float *h = realloc(cn, cap * 12 * sizeof *h);
                if (h)
                    cn = h;
                if (!g || !h) {
                    free(q);
                    free(cn);
                    return -1;
                }
            }
            /* Counter-clockwise about +a when the inside is at the edge's start. */
            static const int fwd[4] = {0, 1, 2, 3}, rev[4] = {0, 3, 2, 1};
            const int *o = in0 ? fwd : rev;
            for (int k = 0; k < 4; k++) {
                int w = idx[o[k]];
                q[4 * n + (size_t)k] = w;
                const float *nw = x->side[w] >= 0 ? x->side_N + 36 * (size_t)x->side[w] +
                                                        3 * (size_t)(4 * a + offset[o[k]])
                                                  : x->N + 3 * (size_t)w;
                memcpy(cn + 12 * n + 3 * (size_t)k, nw, 3 * sizeof *nw);
            }
            n++;
        }
    }
    out->quads = q;
    out->corner_N = cn;
    out->n_quads = n;
    return 0;
}

int blobby_polygonize(const Blobby *b, float cell, size_t max_points, BlobbyMesh *out, char *msg,
                      size_t n_msg)
{
    memset(out, 0, sizeof *out);
    Bounds3 box = leaves_bound(b);
    if (!(box.lo.x <= box.hi.x))
        return 0; /* no leaf with a bounded field: nothing to draw */
    float diag = v3_length(v3_sub(box.hi, box.lo));
    float h = cell > 0.0f ? cell : blobby_default_cell(b);
    h = fmaxf(h, diag / 4096.0f);
    if (!(h > 0.0f) || !isfinite(h))
        return 0;
    Nets x = {.b = b, .h = h, .max_points = max_points};
    x.origin = v3_sub(box.lo, v3(2 * h, 2 * h, 2 * h));
    Vec3 ext = v3_sub(box.hi, box.lo);
    x.n[0] = (int)ceilf(ext.x / h) + 4;
    x.n[1] = (int)ceilf(ext.y / h) + 4;
    x.n[2] = (int)ceilf(ext.z / h) + 4;
    size_t ni = b->n_instr, nl = b->n_leaves ? b->n_leaves : 1;
    x.val = malloc(3 * ni * sizeof *x.val);
    x.grad = malloc(ni * sizeof *x.grad);
    x.leaf_lo = calloc(2 * nl, sizeof *x.leaf_lo);
    x.active = malloc((size_t)MAX_DEPTH * nl * sizeof *x.active);
    x.live = malloc(ni * sizeof *x.live);
    x.live_first = malloc(2 * ni * sizeof *x.live_first);
    x.live_args = malloc((b->n_args ? b->n_args : 1) * sizeof *x.live_args);
    int *all = malloc(nl * sizeof *all);
    int e = 0;
    if (!x.val || !x.grad || !x.leaf_lo || !x.active || !x.live || !x.live_first || !x.live_args ||
        !all)
        e = -1;
    else {
        x.vlo = x.val + ni, x.vhi = x.val + 2 * ni;
        x.leaf_hi = x.leaf_lo + nl;
        x.live_n = x.live_first + ni;
        size_t n_all = 0;
        for (size_t i = 0; i < b->n_leaves; i++)
            all[n_all++] = (int)i;
        int lo[3] = {0, 0, 0};
        descend(&x, lo, x.n, all, n_all, 0);
        e = x.status;
        if (e == 0 && make_quads(&x, out) != 0)
            e = -1;
    }
    free(all);
    free(x.val);
    free(x.grad);
    free(x.leaf_lo);
    free(x.active);
    free(x.live);
    free(x.live_first);
    free(x.live_args);
    free(x.cell);
    free(x.mask);
    free(x.side);
    free(x.side_N);
    free(x.keys);
    free(x.slot);
    if (e != 0) {
        free(x.P);
        free(x.N);
        blobby_mesh_free(out);
        if (e < 0)
            failf(msg, n_msg, "out of memory");
        return e;
    }
    out->P = x.P, out->N = x.N;
    out->n_points = x.n_points;
    out->cell = h;
    return 0;
}
