/* Small dense linear algebra (linalg.h). */
#include "analysis/linalg.h"

#include <math.h>

bool linalg_cholesky(double *a, size_t n)
{
    for (size_t j = 0; j < n; j++) {
        double d = a[j * n + j];
        for (size_t k = 0; k < j; k++)
            d -= a[j * n + k] * a[j * n + k];
        if (!(d > 0.0) || !isfinite(d))
            return false;
        double ljj = sqrt(d);
        a[j * n + j] = ljj;
        for (size_t i = j + 1; i < n; i++) {
            double s = a[i * n + j];
            for (size_t k = 0; k < j; k++)
                s -= a[i * n + k] * a[j * n + k];
            a[i * n + j] = s / ljj;
        }
    }
    return true;
}

void linalg_cholesky_solve(const double *l, size_t n, const double *b, double *x)
{
    for (size_t i = 0; i < n; i++) { /* L y = b */
        double s = b[i];
        for (size_t k = 0; k < i; k++)
            s -= l[i * n + k] * x[k];
        x[i] = s / l[i * n + i];
    }
    for (size_t i = n; i-- > 0;) { /* L^T x = y */
        double s = x[i];
        for (size_t k = i + 1; k < n; k++)
            s -= l[k * n + i] * x[k];
        x[i] = s / l[i * n + i];
    }
}

double linalg_cholesky_quad(const double *l, size_t n, const double *v, double *work)
{
    /* v^T (L L^T)^-1 v = |L^-1 v|^2 */
    double q = 0.0;
    for (size_t i = 0; i < n; i++) {
        double s = v[i];
        for (size_t k = 0; k < i; k++)
            s -= l[i * n + k] * work[k];
        work[i] = s / l[i * n + i];
        q += work[i] * work[i];
    }
    return q;
}

double linalg_cholesky_logdet(const double *l, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += log(l[i * n + i]);
    return 2.0 * s;
}

void linalg_add_ridge(double *a, size_t n, double ridge)
{
    double trace = 0.0;
    for (size_t i = 0; i < n; i++)
        trace += a[i * n + i];
    double scale = trace > 0.0 && isfinite(trace) ? trace / (double)n : 1.0;
    for (size_t i = 0; i < n; i++)
        a[i * n + i] += ridge * scale;
}
