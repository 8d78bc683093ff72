/* Small dense linear algebra for the analysis modules (classification, band
 * selection): symmetric positive definite matrices of a few to a few hundred rows,
 * row-major doubles. Nothing here allocates.
 */
#ifndef THZ_ANALYSIS_LINALG_H
#define THZ_ANALYSIS_LINALG_H

#include <stdbool.h>
#include <stddef.h>

/* Cholesky factor of the n x n symmetric matrix a in place: its lower triangle becomes
 * L with a = L L^T (the upper triangle is left as it was). False when a is not
 * positive definite (a pivot <= 0 or not finite). */
bool linalg_cholesky(double *a, size_t n);

/* Solves L L^T x = b with the factor of linalg_cholesky; x may be b. */
void linalg_cholesky_solve(const double *l, size_t n, const double *b, double *x);

/* The quadratic form v^T A^-1 v from A's Cholesky factor; `work` holds n doubles. */
double linalg_cholesky_quad(const double *l, size_t n, const double *v, double *work);

/* ln det A from A's Cholesky factor. */
double linalg_cholesky_logdet(const double *l, size_t n);

/* Adds ridge * (trace / n, or 1 when the trace is 0) to the diagonal: the regularisation
 * that makes a sample covariance of fewer samples than dimensions invertible. */
void linalg_add_ridge(double *a, size_t n, double ridge);

#endif
