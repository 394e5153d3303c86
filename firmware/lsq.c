/* Gaussian elimination for the registrations' normal equations. */
#include "lsq.h"

#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <string.h>

int lsq_solve(uint32_t n, double *a, double *b, double *x)
{
    double scale = 0.0;
    for (uint32_t i = 0; i < n; i++)
        scale = fmax(scale, fabs(a[(size_t)i * n + i]));
    if (scale <= 0.0)
        return -EDOM;
    uint32_t rank = 0;
    for (uint32_t c = 0; c < n; c++) {
        uint32_t piv = c;
        for (uint32_t r = c + 1; r < n; r++)
            if (fabs(a[(size_t)r * n + c]) > fabs(a[(size_t)piv * n + c]))
                piv = r;
        for (uint32_t k = 0; k < n && piv != c; k++) {
            double t = a[(size_t)c * n + k];
            a[(size_t)c * n + k] = a[(size_t)piv * n + k];
            a[(size_t)piv * n + k] = t;
        }
        double t = b[c];
        b[c] = b[piv];
        b[piv] = t;
        double d = a[(size_t)c * n + c];
        if (fabs(d) < 1e-12 * scale) { /* undetermined: leave this unknown at 0 */
            a[(size_t)c * n + c] = 0.0;
            continue;
        }
        rank++;
        for (uint32_t r = c + 1; r < n; r++) {
            double f = a[(size_t)r * n + c] / d;
            if (f == 0.0)
                continue;
            for (uint32_t k = c; k < n; k++)
                a[(size_t)r * n + k] -= f * a[(size_t)c * n + k];
            b[r] -= f * b[c];
        }
    }
    for (uint32_t r = n; r-- > 0;) {
        double d = a[(size_t)r * n + r];
        if (d == 0.0) {
            x[r] = 0.0;
            continue;
        }
        double s = b[r];
        for (uint32_t k = r + 1; k < n; k++)
            s -= a[(size_t)r * n + k] * x[k];
        x[r] = s / d;
    }
    return rank > 0 ? 0 : -EDOM;
}

void lsq_rigid_clear(struct lsq_rigid *eq)
{
    memset(eq, 0, sizeof(*eq));
}

void lsq_rigid_add(struct lsq_rigid *eq, vec3 p, vec3 q, vec3 n)
{
    double res = v3_dot(v3_sub(p, q), n);
    vec3 pxn = v3_cross(p, n);
    const double jac[6] = {pxn.x, pxn.y, pxn.z, n.x, n.y, n.z};
    for (int r = 0; r < 6; r++) {
        for (int c = 0; c < 6; c++)
            eq->a[r * 6 + c] += jac[r] * jac[c];
        eq->b[r] -= jac[r] * res;
    }
    eq->sq += res * res;
    eq->pairs++;
}

int lsq_rigid_step(struct lsq_rigid *eq, struct frame_xform *step)
{
    double x[6];
    if (eq->pairs < 6 || lsq_solve(6, eq->a, eq->b, x) != 0)
        return -EDOM;
    frame_from_small_motion(x, step);
    return 0;
}

double lsq_rigid_shift_hold(const struct lsq_rigid *eq)
{
    /* The shift block of the normal equations (jac[3..5] = n): a symmetric 3 x 3 matrix, its
     * eigenvalues in closed form (the trigonometric solution of its characteristic cubic). */
    const double *a = eq->a;
    double m[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            m[r][c] = a[(r + 3) * 6 + (c + 3)];
    double trace = m[0][0] + m[1][1] + m[2][2];
    if (trace <= 0.0)
        return 0.0;
    double off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
    double q = trace / 3.0, smallest;
    if (off == 0.0) {
        smallest = fmin(m[0][0], fmin(m[1][1], m[2][2]));
    } else {
        double p2 = (m[0][0] - q) * (m[0][0] - q) + (m[1][1] - q) * (m[1][1] - q) +
                    (m[2][2] - q) * (m[2][2] - q) + 2.0 * off;
        double p = sqrt(p2 / 6.0), b[3][3];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                b[r][c] = (m[r][c] - (r == c ? q : 0.0)) / p;
        double det = b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1]) -
                     b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0]) +
                     b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0]);
        double r = fmin(1.0, fmax(-1.0, det / 2.0));
        smallest = q + 2.0 * p * cos(acos(r) / 3.0 + 2.0 * M_PI / 3.0);
    }
    return fmax(0.0, smallest) / trace;
}
