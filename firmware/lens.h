/* Lens distortion (Brown-Conrady, OpenCV's order k1, k2, p1, p2, k3) for the camera and the
 * projector: shared by triangulation, the simulator and calibration, so all agree on the model. */
#ifndef LENS_H
#define LENS_H

/** Index of each coefficient in a distortion array of LENS_COEFFS doubles. */
enum { LENS_K1 = 0, LENS_K2, LENS_P1, LENS_P2, LENS_K3, LENS_COEFFS };

/** 1 if every coefficient is 0 (a pinhole: nothing to do). Inline: asked once a pixel. */
static inline int lens_is_pinhole(const double dist[LENS_COEFFS])
{
    for (int i = 0; i < LENS_COEFFS; i++)
        if (dist[i] != 0.0)
            return 0;
    return 1;
}

/** Distort normalised image coordinates (x = X/Z, y = Y/Z):
 *  r2 = x^2 + y^2, radial = 1 + k1 r2 + k2 r2^2 + k3 r2^3,
 *  xd = x radial + 2 p1 x y + p2 (r2 + 2 x^2),  yd = y radial + p1 (r2 + 2 y^2) + 2 p2 x y.
 *  @param dist  the coefficients @param x, y  undistorted @param xd, yd  out: distorted */
void lens_distort(const double dist[LENS_COEFFS], double x, double y, double *xd, double *yd);

/** Jacobian of lens_distort at (x, y), row-major: [dxd/dx, dxd/dy, dyd/dx, dyd/dy]. */
void lens_jacobian(const double dist[LENS_COEFFS], double x, double y, double j[4]);

/** Invert lens_distort by Newton's method on the 2x2 Jacobian (a few iterations converge to
 *  1e-12 for any lens a calibration accepts).
 *  @param xd, yd  distorted @param x, y  out: undistorted
 *  @retval 0 ok @retval -EDOM no convergence (a point beyond where the model folds over) */
int lens_undistort(const double dist[LENS_COEFFS], double xd, double yd, double *x, double *y);

#endif
