/* Keyframe interpolation in time (scene-format.md "Sequences, sweeps and movies"):
 * linear for numbers and vectors, quaternion slerp for rotations, the end values held
 * beyond the first and last keyframe. The segment weights are exact at the keyframes
 * ((1 - u) a + u b), so a frame at a keyframe's time gets the keyframe's value bit for bit;
 * a value both ends of a segment give alike is that value throughout (the weights' sum
 * would move it in its last bit, and a still object would then differ from frame to frame).
 */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "batch/batch_internal.h"

void batch_segment(const double *t, size_t k, double time_s, size_t *j, double *u)
{
    if (k <= 1 || time_s <= t[0]) {
        *j = 0;
        *u = 0.0;
        return;
    }
    if (time_s >= t[k - 1]) {
        *j = k - 2;
        *u = 1.0;
        return;
    }
    size_t s = 0;
    while (s + 2 < k && time_s >= t[s + 1])
        s++;
    *j = s;
    *u = (time_s - t[s]) / (t[s + 1] - t[s]);
}

void thz_interp_linear(const double *t, const double *v, size_t k, size_t n, double time_s,
                       double *out)
{
    if (k == 0 || !t || !v || !out) /* void functions do nothing on NULL (thzmap.h) */
        return;
    size_t j;
    double u;
    batch_segment(t, k, time_s, &j, &u);
    for (size_t m = 0; m < n; m++) {
        double a = v[j * n + m];
        double b = k > 1 ? v[(j + 1) * n + m] : a;
        out[m] = u == 0.0 || a == b ? a : u == 1.0 ? b : (1.0 - u) * a + u * b;
    }
}

/* Quaternions (w, x, y, z) of the scene's rotation convention: about x, then y, then z,
 * i.e. q = qz * qy * qx (scene/transform.c applies R = Rz Ry Rx). */
static void quat_mul(const double a[4], const double b[4], double out[4])
{
    out[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    out[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    out[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    out[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}

static void quat_from_deg(const double deg[3], double q[4])
{
    const double rad = M_PI / 180.0;
    double qx[4] = {cos(0.5 * deg[0] * rad), sin(0.5 * deg[0] * rad), 0, 0};
    double qy[4] = {cos(0.5 * deg[1] * rad), 0, sin(0.5 * deg[1] * rad), 0};
    double qz[4] = {cos(0.5 * deg[2] * rad), 0, 0, sin(0.5 * deg[2] * rad)};
    double zy[4];
    quat_mul(qz, qy, zy);
    quat_mul(zy, qx, q);
}

/* The angles (about x, y, z; R = Rz Ry Rx) of a unit quaternion, in degrees. */
static void quat_to_deg(const double q[4], double deg[3])
{
    double w = q[0], x = q[1], y = q[2], z = q[3];
    double r20 = 2.0 * (x * z - w * y); /* R[2][0] = -sin(ry) */
    double r21 = 2.0 * (y * z + w * x);
    double r22 = 1.0 - 2.0 * (x * x + y * y);
    double r10 = 2.0 * (x * y + w * z);
    double r00 = 1.0 - 2.0 * (y * y + z * z);
    double s = fmax(-1.0, fmin(1.0, -r20));
    const double to_deg = 180.0 / M_PI;
    deg[1] = asin(s) * to_deg;
    if (fabs(s) < 1.0 - 1e-12) {
        deg[0] = atan2(r21, r22) * to_deg;
        deg[2] = atan2(r10, r00) * to_deg;
    } else { /* gimbal lock: only rx - rz (or rx + rz) is defined; put it all in rz */
        double r01 = 2.0 * (x * y - w * z);
        double r11 = 1.0 - 2.0 * (x * x + z * z);
        deg[0] = 0.0;
        deg[2] = atan2(-r01, r11) * to_deg;
    }
}

void thz_interp_rotation(const double *t, const double *rotate_deg, size_t k, double time_s,
                         double out_deg[3])
{
    if (k == 0 || !t || !rotate_deg || !out_deg)
        return;
    size_t j;
    double u;
    batch_segment(t, k, time_s, &j, &u);
    const double *ra = &rotate_deg[j * 3], *rb = k > 1 ? &rotate_deg[(j + 1) * 3] : ra;
    bool same = ra[0] == rb[0] && ra[1] == rb[1] && ra[2] == rb[2];
    if (k == 1 || u == 0.0 || u == 1.0 || same) { /* a keyframe's own angles, as written */
        const double *src = u == 1.0 ? rb : ra;
        for (int m = 0; m < 3; m++)
            out_deg[m] = src[m];
        return;
    }
    double a[4], b[4];
    quat_from_deg(&rotate_deg[j * 3], a);
    quat_from_deg(&rotate_deg[(j + 1) * 3], b);
    double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    if (d < 0.0) { /* q and -q are the same rotation: take the shorter arc */
        for (int m = 0; m < 4; m++)
            b[m] = -b[m];
        d = -d;
    }
    double wa, wb;
    if (d > 1.0 - 1e-12) { /* (nearly) the same rotation: lerp is exact enough */
        wa = 1.0 - u;
        wb = u;
    } else {
        double theta = acos(d);
        wa = sin((1.0 - u) * theta) / sin(theta);
        wb = sin(u * theta) / sin(theta);
    }
    double q[4], norm = 0.0;
    for (int m = 0; m < 4; m++) {
        q[m] = wa * a[m] + wb * b[m];
        norm += q[m] * q[m];
    }
    norm = sqrt(norm);
    for (int m = 0; m < 4; m++)
        q[m] /= norm;
    quat_to_deg(q, out_deg);
}
