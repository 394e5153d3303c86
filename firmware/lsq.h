/* Small dense least-squares helpers shared by the registrations: normal equations solved in
 * place. */
#ifndef LSQ_H
#define LSQ_H

#include <stdint.h>

#include "frames.h"
#include "vec3.h"

/** Solve a x = b for symmetric positive semi-definite @p a (n x n, row-major) by Gaussian
 *  elimination with partial pivoting; @p a and @p b are consumed. A direction the equations
 *  do not determine (a pivot below 1e-12 of the largest) gets x = 0 there.
 *  @retval 0 @retval -EDOM nothing determined at all */
int lsq_solve(uint32_t n, double *a, double *b, double *x);

/** Normal equations of point-to-plane rigid registration (Chen and Medioni 1992; Low 2004):
 *  the small motion x = (omega, t) that moves points p towards the planes (q, n), linearised:
 *  r = (p - q) . n + omega . (p x n) + t . n. */
struct lsq_rigid {
    double a[36], b[6];
    double sq;      /**< sum of the squared residuals added */
    uint32_t pairs; /**< pairs added */
};

/** Empty equations. */
void lsq_rigid_clear(struct lsq_rigid *eq);

/** How well the pairs added hold a shift in every direction: the smallest eigenvalue of the sum
 *  of n n^T over their normals, over its trace: 1/3 for normals spread evenly, 0 when every
 *  normal lies in one plane (two parallel faces and a top), so that a shift at right angles to
 *  that plane changes no residual. @retval 0 .. 1/3 */
double lsq_rigid_shift_hold(const struct lsq_rigid *eq);

/** The directions the pairs hold a shift in, from the weakest: @p share the eigenvalues of the
 *  sum of n n^T over its trace (ascending, summing to 1), @p axis their unit eigenvectors.
 *  @retval 0 @retval -EDOM no pairs */
int lsq_rigid_shift_axes(const struct lsq_rigid *eq, double share[3], vec3 axis[3]);

/** Add the pair of point @p p and the plane through @p q with unit normal @p n. */
void lsq_rigid_add(struct lsq_rigid *eq, vec3 p, vec3 q, vec3 n);

/** Add one residual @p res with its derivatives @p jac by (omega, t), weighted @p weight, to the
 *  equations only (not to sq or pairs): a residual other than a point-to-plane distance (a
 *  colour's, reg_place.c). */
void lsq_rigid_add_row(struct lsq_rigid *eq, const double jac[6], double res, double weight);

/** Solve (consumes @p eq) for the step that moves the points: out(p) = R p + t.
 *  @retval 0 @retval -EDOM fewer than 6 pairs or nothing determined */
int lsq_rigid_step(struct lsq_rigid *eq, struct frame_xform *step);

#endif
