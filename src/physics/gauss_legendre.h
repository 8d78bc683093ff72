/* Gauss-Legendre quadrature on [0, 1] with GAUSS_LEGENDRE_NODES nodes: exact for
 * polynomials of degree < 2 x nodes, and converging exponentially for the analytic
 * functions of mu that the angle-dependent optics integrate (optics.c, brdf.c). */
#ifndef THZ_PHYSICS_GAUSS_LEGENDRE_H
#define THZ_PHYSICS_GAUSS_LEGENDRE_H

#define GAUSS_LEGENDRE_NODES 48

/* Nodes in increasing order, and their weights (summing to 1). */
extern const double gauss_legendre_x[GAUSS_LEGENDRE_NODES];
extern const double gauss_legendre_w[GAUSS_LEGENDRE_NODES];

#endif
