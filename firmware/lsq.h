/* Small dense least-squares helpers shared by the registrations: normal equations solved in
 * place. */
#ifndef LSQ_H
#define LSQ_H

#include <stdint.h>

/** Solve a x = b for symmetric positive semi-definite @p a (n x n, row-major) by Gaussian
 *  elimination with partial pivoting; @p a and @p b are consumed. A direction the equations
 *  do not determine (a pivot below 1e-12 of the largest) gets x = 0 there.
 *  @retval 0 @retval -EDOM nothing determined at all */
int lsq_solve(uint32_t n, double *a, double *b, double *x);

#endif
