/* Small 3-vector math in double precision (positions in metres, unit directions). */
#ifndef THZ_CORE_VEC3_H
#define THZ_CORE_VEC3_H

#include <math.h>

typedef struct vec3 {
    double x, y, z;
} vec3;

static inline vec3 v3(double x, double y, double z)
{
    return (vec3){x, y, z};
}
static inline vec3 v3_add(vec3 a, vec3 b)
{
    return v3(a.x + b.x, a.y + b.y, a.z + b.z);
}
static inline vec3 v3_sub(vec3 a, vec3 b)
{
    return v3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static inline vec3 v3_scale(vec3 a, double s)
{
    return v3(a.x * s, a.y * s, a.z * s);
}
/* a + s*b */
static inline vec3 v3_madd(vec3 a, double s, vec3 b)
{
    return v3(a.x + s * b.x, a.y + s * b.y, a.z + s * b.z);
}
static inline double v3_dot(vec3 a, vec3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static inline vec3 v3_cross(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double v3_length(vec3 a)
{
    return sqrt(v3_dot(a, a));
}
/* Unit vector along a; a zero vector stays zero. */
static inline vec3 v3_normalize(vec3 a)
{
    double l = v3_length(a);
    return l > 0.0 ? v3_scale(a, 1.0 / l) : a;
}
static inline vec3 v3_from_array(const double a[3])
{
    return v3(a[0], a[1], a[2]);
}
static inline vec3 v3_from_floats(const float a[3])
{
    return v3(a[0], a[1], a[2]);
}

/* An orthonormal basis (t, b, n) around the unit vector n (Duff et al. 2017). */
static inline void v3_basis(vec3 n, vec3 *t, vec3 *b)
{
    double sign = copysign(1.0, n.z);
    double a = -1.0 / (sign + n.z);
    double c = n.x * n.y * a;
    *t = v3(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
    *b = v3(c, sign + n.y * n.y * a, -n.y);
}

#endif
