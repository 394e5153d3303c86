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

void lsq_rigid_add_row(struct lsq_rigid *eq, const double jac[6], double res, double weight)
{
    for (int r = 0; r < 6; r++) {
        for (int c = 0; c < 6; c++)
            eq->a[r * 6 + c] += weight * jac[r] * jac[c];
        eq->b[r] -= weight * jac[r] * res;
    }
}

void lsq_rigid_add(struct lsq_rigid *eq, vec3 p, vec3 q, vec3 n)
{
    double res = v3_dot(v3_sub(p, q), n);
    vec3 pxn = v3_cross(p, n);
    const double jac[6] = {pxn.x, pxn.y, pxn.z, n.x, n.y, n.z};
    lsq_rigid_add_row(eq, jac, res, 1.0);
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

/* Cyclic Jacobi rotations (Golub and Van Loan, 8.5) on the 3 x 3 shift block (jac[3..5] = n):
 * its eigenvalues, ascending, over its trace, and their unit eigenvectors. */
int lsq_rigid_shift_axes(const struct lsq_rigid *eq, double share[3], vec3 axis[3])
{
    double m[3][3], v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            m[r][c] = eq->a[(r + 3) * 6 + (c + 3)];
    double trace = m[0][0] + m[1][1] + m[2][2];
    if (!(trace > 0.0))
        return -EDOM;
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
        if (off <= 1e-30 * trace * trace)
            break;
        for (int p = 0; p < 2; p++) {
            for (int q = p + 1; q < 3; q++) {
                if (m[p][q] == 0.0)
                    continue;
                double theta = (m[q][q] - m[p][p]) / (2.0 * m[p][q]);
                double t = (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; k++) { /* m <- m J (columns p, q) */
                    double a = m[k][p], b = m[k][q];
                    m[k][p] = c * a - s * b, m[k][q] = s * a + c * b;
                }
                for (int k = 0; k < 3; k++) { /* m <- J^T m (rows p, q) */
                    double a = m[p][k], b = m[q][k];
                    m[p][k] = c * a - s * b, m[q][k] = s * a + c * b;
                }
                for (int k = 0; k < 3; k++) { /* eigenvectors: the columns of v J */
                    double a = v[k][p], b = v[k][q];
                    v[k][p] = c * a - s * b, v[k][q] = s * a + c * b;
                }
            }
        }
    }
    int order[3] = {0, 1, 2};
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            if (m[order[j]][order[j]] < m[order[i]][order[i]]) {
                int t = order[i];
                order[i] = order[j], order[j] = t;
            }
    for (int i = 0; i < 3; i++) {
        int k = order[i];
        share[i] = fmax(0.0, m[k][k]) / trace;
        axis[i] = v3(v[0][k], v[1][k], v[2][k]);
    }
    return 0;
}

double lsq_rigid_shift_hold(const struct lsq_rigid *eq)
{
    double share[3];
    vec3 axis[3];
    return lsq_rigid_shift_axes(eq, share, axis) == 0 ? share[0] : 0.0;
}
