/* models/linalg.h - the little dense linear algebra the models need
 * (matrices of at most CM_MAX_DIM x CM_MAX_DIM, row-major). */
#ifndef CM_MODELS_LINALG_H
#define CM_MODELS_LINALG_H

#include <stdbool.h>

/* c (n x m) = a (n x k) * b (k x m); c must not alias a or b. */
void cm_mat_mul(int n, int k, int m, const double *a, const double *b, double *c);

/* y (n) = a (n x m) * x (m); y must not alias x. */
void cm_mat_vec(int n, int m, const double *a, const double *x, double *y);

/* inv = a^-1 for n x n a, by Gauss-Jordan with partial pivoting.
 * Returns false when a is singular to working precision. */
bool cm_mat_inverse(int n, const double *a, double *inv);

#endif
