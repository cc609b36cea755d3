/*
 * render/irradiance.c — the gradient formulas of the technical digest,
 * section 3.4, for the stratified sampler of irradiance.h.
 *
 * In the record's frame, cell (j, k) has centre theta_j, phi_k =
 * 2 pi (k + 1/2) / N; walls theta_j- = asin(sqrt(j/M)), theta_j+ =
 * asin(sqrt((j+1)/M)); u_k = (cos phi_k, sin phi_k, 0), v_k = (-sin phi_k,
 * cos phi_k, 0), and v_k- the direction at phi = 2 pi k / N + pi/2 (the
 * wall between cells k-1 and k).
 *
 *   grad_r = pi/(MN) sum_k v_k sum_j tan(theta_j) L_jk
 *   grad_t = sum_k [ u_k (2 pi/N) sum_{j>=1} sin(theta_j-) cos^2(theta_j-)
 *                        (L_jk - L_j-1,k) / min(r_jk, r_j-1,k)
 *                  + v_k- sum_j (sin theta_j+ - sin theta_j-) (L_jk - L_j,k-1)
 *                        / min(r_jk, r_j,k-1) ]
 *
 * tests/render/test_irradiance.c checks both against finite differences.
 */
#include "render/irradiance.h"

#include <math.h>

void irr_frame(Vec3 n, Vec3 *t, Vec3 *b)
{
    v3_basis(n, t, b);
}

Vec3 irr_direction(int M, int N, int j, int k, float xi1, float xi2, Vec3 n)
{
    Vec3 t, b;
    irr_frame(n, &t, &b);
    float s2 = ((float)j + xi1) / (float)M;
    float sin_t = sqrtf(s2), cos_t = sqrtf(fmaxf(0.0f, 1.0f - s2));
    float phi = 2.0f * (float)M_PI * ((float)k + xi2) / (float)N;
    return v3_add(v3_add(v3_scale(t, sin_t * cosf(phi)), v3_scale(b, sin_t * sinf(phi))),
                  v3_scale(n, cos_t));
}

static float comp(Vec3 v, int c)
{
    return c == 0 ? v.x : c == 1 ? v.y : v.z;
}

static void add_comp(Vec3 *g, int c, Vec3 dir, float s)
{
    g[c] = v3_madd(g[c], dir, s);
}

void irr_record(int M, int N, const Vec3 *L, const float *r, Vec3 p, Vec3 n, IrrRecord *rec)
{
    Vec3 t, b;
    irr_frame(n, &t, &b);
    Vec3 zero = v3(0, 0, 0), sum = zero;
    IrrRadius radius = IRR_RADIUS_INIT;
    rec->p = p;
    rec->n = n;
    for (int c = 0; c < 3; c++)
        rec->grad_r[c] = rec->grad_t[c] = zero;
    for (int k = 0; k < N; k++) {
        float phi = 2.0f * (float)M_PI * ((float)k + 0.5f) / (float)N;
        float phi_wall = 2.0f * (float)M_PI * (float)k / (float)N + 0.5f * (float)M_PI;
        Vec3 u_k = v3_add(v3_scale(t, cosf(phi)), v3_scale(b, sinf(phi)));
        Vec3 v_k = v3_add(v3_scale(t, -sinf(phi)), v3_scale(b, cosf(phi)));
        Vec3 v_wall = v3_add(v3_scale(t, cosf(phi_wall)), v3_scale(b, sinf(phi_wall)));
        int km = (k + N - 1) % N;
        for (int j = 0; j < M; j++) {
            int i = j * N + k;
            sum = v3_add(sum, L[i]);
            float s2 = ((float)j + 0.5f) / (float)M;
            float cos_c = sqrtf(1.0f - s2), tan_c = sqrtf(s2) / cos_c;
            irr_radius_add(&radius, r[i], cos_c);
            float sin_lo = sqrtf((float)j / (float)M), sin_hi = sqrtf((float)(j + 1) / (float)M);
            float cos2_lo = 1.0f - (float)j / (float)M;
            for (int c = 0; c < 3; c++) {
                add_comp(rec->grad_r, c, v_k, tan_c * comp(L[i], c));
                /* across the wall to the cell below (toward the pole) */
                if (j > 0) {
                    int below = (j - 1) * N + k;
                    float rr = fminf(r[i], r[below]);
                    if (isfinite(rr) && rr > 0.0f)
                        add_comp(rec->grad_t, c, u_k,
                                 2.0f * (float)M_PI / (float)N * sin_lo * cos2_lo *
                                     (comp(L[i], c) - comp(L[below], c)) / rr);
                }
                /* across the wall to the previous cell in phi */
                int prev = j * N + km;
                float rr = fminf(r[i], r[prev]);
                if (isfinite(rr) && rr > 0.0f)
                    add_comp(rec->grad_t, c, v_wall,
                             (sin_hi - sin_lo) * (comp(L[i], c) - comp(L[prev], c)) / rr);
            }
        }
    }
    float cell = (float)M_PI / (float)(M * N);
    rec->E = v3_scale(sum, cell);
    for (int c = 0; c < 3; c++)
        rec->grad_r[c] = v3_scale(rec->grad_r[c], cell);
    rec->R = irr_radius(&radius);
}

void irr_radius_add(IrrRadius *acc, float r, float cos_theta)
{
    acc->n++;
    if (!isfinite(r) || !(r > 0.0f))
        return;
    acc->inv_r += 1.0 / r;
    if (cos_theta > 0.173f) /* samples within ~10 degrees of the tangent plane do not set R */
        acc->r_min = fminf(acc->r_min, r);
}

float irr_radius(const IrrRadius *acc)
{
    if (isfinite(acc->r_min))
        return acc->r_min;
    return acc->inv_r > 0.0 ? (float)(acc->n / acc->inv_r) : INFINITY;
}

Vec3 irr_extrapolate(const IrrRecord *rec, Vec3 p, Vec3 n)
{
    Vec3 axis = v3_cross(rec->n, n), d = v3_sub(p, rec->p);
    float e[3];
    for (int c = 0; c < 3; c++)
        e[c] = fmaxf(0.0f, comp(rec->E, c) + v3_dot(axis, rec->grad_r[c]) +
                               v3_dot(d, rec->grad_t[c]));
    return v3(e[0], e[1], e[2]);
}

float irr_weight(const IrrRecord *rec, Vec3 p, Vec3 n, float kappa)
{
    Vec3 d = v3_sub(p, rec->p);
    /* A record in front of p (d below the mean tangent plane) does not see what p sees. */
    if (v3_dot(d, v3_add(n, rec->n)) < -1e-4f * rec->R)
        return 0.0f;
    float ep = v3_length(d) / rec->R;
    float en = sqrtf(fmaxf(0.0f, 1.0f - v3_dot(n, rec->n))) / sqrtf(1.0f - cosf(10.0f * (float)M_PI / 180.0f));
    float w = 1.0f - kappa * fmaxf(ep, en);
    return w > 0.0f ? w : 0.0f;
}
