/*
 * util/vec.c — the out-of-line matrix operations of vec.h. Pure functions;
 * thread-safe.
 */
#include "util/vec.h"

#include <string.h>

Mat4 mat4_identity(void)
{
    Mat4 r = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
    return r;
}

Mat4 mat4_mul(Mat4 a, Mat4 b)
{
    Mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0.0; /* double: products of long transform chains stay exact longer */
            for (int k = 0; k < 4; k++)
                s += (double)a.m[i][k] * b.m[k][j];
            r.m[i][j] = (float)s;
        }
    return r;
}

Mat4 mat4_translate(float x, float y, float z)
{
    Mat4 r = mat4_identity();
    r.m[0][3] = x;
    r.m[1][3] = y;
    r.m[2][3] = z;
    return r;
}

Mat4 mat4_scale(float x, float y, float z)
{
    Mat4 r = mat4_identity();
    r.m[0][0] = x;
    r.m[1][1] = y;
    r.m[2][2] = z;
    return r;
}

Mat4 mat4_rotate(float angle_degrees, Vec3 axis)
{
    Vec3 a = v3_normalize(axis);
    double th = angle_degrees * (M_PI / 180.0);
    float s = (float)sin(th), c = (float)cos(th), t = 1.0f - c;
    Mat4 r = mat4_identity();
    r.m[0][0] = t * a.x * a.x + c;
    r.m[0][1] = t * a.x * a.y - s * a.z;
    r.m[0][2] = t * a.x * a.z + s * a.y;
    r.m[1][0] = t * a.x * a.y + s * a.z;
    r.m[1][1] = t * a.y * a.y + c;
    r.m[1][2] = t * a.y * a.z - s * a.x;
    r.m[2][0] = t * a.x * a.z - s * a.y;
    r.m[2][1] = t * a.y * a.z + s * a.x;
    r.m[2][2] = t * a.z * a.z + c;
    return r;
}

Mat4 mat4_transpose(Mat4 m)
{
    Mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r.m[i][j] = m.m[j][i];
    return r;
}

Mat4 mat4_from_array(const float a[16])
{
    Mat4 r;
    memcpy(r.m, a, sizeof r.m);
    return r;
}

/* Gauss-Jordan elimination with partial pivoting, in double precision. */
int mat4_invert(Mat4 m, Mat4 *inv)
{
    double a[4][8];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 8; j++)
            a[i][j] = j < 4 ? m.m[i][j] : (j - 4 == i);
    for (int c = 0; c < 4; c++) {
        int p = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[p][c]))
                p = r;
        if (fabs(a[p][c]) < 1e-30) {
            *inv = mat4_identity();
            return 0;
        }
        for (int j = 0; j < 8; j++) {
            double t = a[c][j];
            a[c][j] = a[p][j];
            a[p][j] = t;
        }
        double d = 1.0 / a[c][c];
        for (int j = 0; j < 8; j++)
            a[c][j] *= d;
        for (int r = 0; r < 4; r++) {
            if (r == c)
                continue;
            double f = a[r][c];
            for (int j = 0; j < 8; j++)
                a[r][j] -= f * a[c][j];
        }
    }
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            inv->m[i][j] = (float)a[i][j + 4];
    return 1;
}
