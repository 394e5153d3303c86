/* Brown-Conrady lens distortion and its inverse (docs/calibration.md, "Lens model"). */
#include "lens.h"

#include <errno.h>
#include <math.h>

void lens_distort(const double d[LENS_COEFFS], double x, double y, double *xd, double *yd)
{
    double r2 = x * x + y * y;
    double radial = 1.0 + r2 * (d[LENS_K1] + r2 * (d[LENS_K2] + r2 * d[LENS_K3]));
    *xd = x * radial + 2.0 * d[LENS_P1] * x * y + d[LENS_P2] * (r2 + 2.0 * x * x);
    *yd = y * radial + d[LENS_P1] * (r2 + 2.0 * y * y) + 2.0 * d[LENS_P2] * x * y;
}

void lens_jacobian(const double d[LENS_COEFFS], double x, double y, double j[4])
{
    double r2 = x * x + y * y;
    double radial = 1.0 + r2 * (d[LENS_K1] + r2 * (d[LENS_K2] + r2 * d[LENS_K3]));
    double dradial_dr2 = d[LENS_K1] + r2 * (2.0 * d[LENS_K2] + 3.0 * r2 * d[LENS_K3]);
    /* d(r2)/dx = 2x, d(r2)/dy = 2y */
    j[0] = radial + x * dradial_dr2 * 2.0 * x + 2.0 * d[LENS_P1] * y + 6.0 * d[LENS_P2] * x;
    j[1] = x * dradial_dr2 * 2.0 * y + 2.0 * d[LENS_P1] * x + 2.0 * d[LENS_P2] * y;
    j[2] = y * dradial_dr2 * 2.0 * x + 2.0 * d[LENS_P1] * x + 2.0 * d[LENS_P2] * y;
    j[3] = radial + y * dradial_dr2 * 2.0 * y + 6.0 * d[LENS_P1] * y + 2.0 * d[LENS_P2] * x;
}

int lens_undistort(const double d[LENS_COEFFS], double xd, double yd, double *x, double *y)
{
    double u = xd, v = yd; /* the distorted point is a good start: distortion is small */
    for (int it = 0; it < 20; it++) {
        double fx, fy, j[4];
        lens_distort(d, u, v, &fx, &fy);
        fx -= xd;
        fy -= yd;
        lens_jacobian(d, u, v, j);
        double det = j[0] * j[3] - j[1] * j[2];
        if (!(det > 1e-12)) /* folded over, or singular */
            return -EDOM;
        double du = (j[3] * fx - j[1] * fy) / det, dv = (j[0] * fy - j[2] * fx) / det;
        u -= du;
        v -= dv;
        if (fabs(du) + fabs(dv) < 1e-13) {
            *x = u;
            *y = v;
            return 0;
        }
    }
    return -EDOM;
}
