/* Small 3-vector and 3x3-matrix helpers (row-major), shared by the firmware and the simulator. */
#ifndef VEC3_H
#define VEC3_H

#include <math.h>

#ifndef M_PI /* POSIX, not ISO C */
#define M_PI 3.14159265358979323846
#endif

typedef struct {
    double x, y, z;
} vec3;

static inline vec3 v3(double x, double y, double z)
{
    vec3 r = {x, y, z};
    return r;
}
static inline vec3 v3_add(vec3 a, vec3 b)
{
    return v3(a.x + b.x, a.y + b.y, a.z + b.z);
}
static inline vec3 v3_sub(vec3 a, vec3 b)
{
    return v3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static inline vec3 v3_scale(vec3 a, double s)
{
    return v3(a.x * s, a.y * s, a.z * s);
}
static inline double v3_dot(vec3 a, vec3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static inline vec3 v3_cross(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double v3_len(vec3 a)
{
    return sqrt(v3_dot(a, a));
}
static inline vec3 v3_norm(vec3 a)
{
    double l = v3_len(a);
    return l > 0.0 ? v3_scale(a, 1.0 / l) : a;
}
/* Two unit vectors across unit @p d, at right angles to each other: a basis of its plane. */
static inline void v3_across(vec3 d, vec3 *e1, vec3 *e2)
{
    vec3 t = fabs(d.x) < 0.9 ? (vec3){1, 0, 0} : (vec3){0, 1, 0};
    *e1 = v3_norm(v3_cross(d, t));
    *e2 = v3_cross(d, *e1);
}
static inline vec3 v3_from(const double a[3])
{
    return v3(a[0], a[1], a[2]);
}
/** m (row-major 3x3) times v. */
static inline vec3 m3_mul(const double m[9], vec3 v)
{
    return v3(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
              m[6] * v.x + m[7] * v.y + m[8] * v.z);
}
/** out = a b (3x3, row-major); @p out may alias neither input. */
static inline void m3_mul_m3(const double a[9], const double b[9], double out[9])
{
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            out[r * 3 + c] = a[r * 3] * b[c] + a[r * 3 + 1] * b[3 + c] + a[r * 3 + 2] * b[6 + c];
}
/** transpose(m) times v. */
static inline vec3 m3_tmul(const double m[9], vec3 v)
{
    return v3(m[0] * v.x + m[3] * v.y + m[6] * v.z, m[1] * v.x + m[4] * v.y + m[7] * v.z,
              m[2] * v.x + m[5] * v.y + m[8] * v.z);
}

#endif
