/* The Voigt profile by Humlicek's W4 algorithm (J. Humlicek, JQSRT 27, 437, 1982),
 * relative accuracy about 1e-4, which is below the line-parameter uncertainties.
 * Used only where the Doppler width matters (low pressure); the ground-level
 * atmosphere is pressure broadened and uses the Lorentz shape. */
#include <complex.h>
#include <math.h>

#include "atmosphere/atm_internal.h"

/* Real part of the Faddeeva function w(x + i y), y >= 0. */
static double humlicek_w4(double x, double y)
{
    double complex t = y - x * I;
    double s = fabs(x) + y;
    double complex w;
    if (s >= 15.0) {
        w = t * 0.5641896 / (0.5 + t * t);
    } else if (s >= 5.5) {
        double complex u = t * t;
        w = t * (1.410474 + u * 0.5641896) / (0.75 + u * (3.0 + u));
    } else if (y >= 0.195 * fabs(x) - 0.176) {
        w = (16.4955 + t * (20.20933 + t * (11.96482 + t * (3.778987 + t * 0.5642236)))) /
            (16.4955 + t * (38.82363 + t * (39.27121 + t * (21.69274 + t * (6.699398 + t)))));
    } else {
        double complex u = t * t;
        w = cexp(u) -
            t * (36183.31 - u * (3321.9905 - u * (1540.787 - u * (219.0313 - u * (35.76683 -
                 u * (1.320522 - u * 0.56419)))))) /
                (32066.6 - u * (24322.84 - u * (9022.228 - u * (2186.181 - u * (364.2191 -
                 u * (61.57037 - u * (1.841439 - u)))))));
    }
    return creal(w);
}

double atm_voigt(double x, double gamma_l, double gamma_d)
{
    double alpha_d = gamma_d / sqrt(M_LN2); /* 1/e half width of the Gaussian */
    return humlicek_w4(x / alpha_d, gamma_l / alpha_d) / (alpha_d * sqrt(M_PI));
}
