#!/usr/bin/env python3
"""Coefficients of optics_expint3 (src/physics/optics.c) and the reference values of
tests/unit/test_optics.c's test_e3_pieces.

E3(x) comes from its convergent series in 60-digit decimal arithmetic (no dependency
beyond the standard library); e^x E3(x) is interpolated at 22 Chebyshev points on
[1, 2], [2, 4] and [4, 8], of which optics.c keeps the first 20 coefficients. The series
coefficients (-1)^(i+1) / (i! (i - 2)), i = 3..18, are printed as well.
"""
from decimal import Decimal as D, getcontext
from fractions import Fraction
import math

getcontext().prec = 60
GAMMA = D('0.577215664901532860606512090082402431042159335939923598805767')
PI = D('3.14159265358979323846264338327950288419716939937510582097494')
POINTS, KEPT = 22, 20


def dcos(x):
    s, term, k = D(0), D(1), 0
    while abs(term) >= D(10) ** -55:
        s += term
        k += 2
        term = -term * x * x / (k * (k - 1))
    return s


def e3(x):
    """E3 = 1/2 - x + x^2/2 (3/2 - gamma - ln x) - sum_{i>=3} (-x)^i / (i! (i - 2))."""
    x = D(x)
    s = D(1) / 2 - x + x * x / 2 * (D(3) / 2 - GAMMA - x.ln())
    term, i = x * x / 2, 2
    while True:
        i += 1
        term = term * (-x) / i
        d = -term / (i - 2)
        s += d
        if abs(d) < D(10) ** -45 and i > 10:
            return s


def chebyshev(a, b):
    nodes = [dcos(PI * (k + D(1) / 2) / POINTS) for k in range(POINTS)]
    values = [e3(D(a + b) / 2 + D(b - a) / 2 * t) * (D(a + b) / 2 + D(b - a) / 2 * t).exp()
              for t in nodes]
    cs = []
    for j in range(POINTS):
        s = sum(values[k] * dcos(PI * j * (k + D(1) / 2) / POINTS) for k in range(POINTS))
        cs.append(s * 2 / POINTS)
    cs[0] /= 2
    return cs[:KEPT]


if __name__ == '__main__':
    print('series:', ', '.join('%.17g' % float(Fraction((-1) ** (i + 1), math.factorial(i) * (i - 2)))
                               for i in range(3, 19)))
    for a, b in [(1, 2), (2, 4), (4, 8)]:
        print('[%d, %d]:' % (a, b), ', '.join('%.17g' % float(c) for c in chebyshev(a, b)))
    for x in ['0.0001', '0.01', '0.1', '1', '1.001', '2', '3', '4', '8', '8.001', '40']:
        print('{%s, %.17g},' % (x, float(e3(x))))
