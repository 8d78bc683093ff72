/* The k-nearest photon search by radius queries: see knn.h. */
#include "photon/knn.h"

#include <math.h>

static void knn_visit(void *vb, const photon_record *p, double distance2_m2)
{
    knn_buffer *b = vb;
    if (!(distance2_m2 <= b->radius2_m2))
        return;
    if (b->n < KNN_CAP)
        b->e[b->n++] = (knn_entry){distance2_m2, p, b->other_side};
    b->total++;
}

/* The k-th smallest of n values (k >= 1, n >= k); reorders v. Quickselect by Lomuto's
 * partition without branches: each value is swapped to the boundary and the boundary
 * moves on when it is below the pivot (a value at or above it trades places with one at
 * or above it). The distances are in no order, so the branches of a partition that tests
 * each value mispredicted about half the time: the select was most of knn_collect's own
 * time. A partition that leaves nothing below the pivot (many values equal to it) then
 * gathers the equal ones, so equal values cost no more than distinct ones. */
static double knn_kth_smallest(double *v, size_t n, size_t k)
{
    size_t lo = 0, hi = n, want = k - 1;
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        double pivot = v[mid];
        v[mid] = v[hi - 1];
        size_t i = lo;
        for (size_t j = lo; j < hi - 1; j++) {
            double x = v[j];
            v[j] = v[i];
            v[i] = x;
            i += x < pivot;
        }
        v[hi - 1] = v[i];
        v[i] = pivot;
        if (want == i)
            return pivot;
        if (want < i) {
            hi = i;
            continue;
        }
        size_t e = i + 1;
        if (i == lo) {
            for (size_t j = e; j < hi; j++) {
                double x = v[j];
                v[j] = v[e];
                v[e] = x;
                e += x == pivot;
            }
            if (want < e)
                return pivot;
        }
        lo = e;
    }
    return v[lo];
}

double knn_collect(const photon_map *map, const photon_map_directory *dir, uint32_t object,
                   double area_m2, int seen_side, unsigned mask, vec3 position, size_t k,
                   knn_buffer *b, double *scratch)
{
    size_t available = photon_map_object_count(map, object, mask);
    if (available < k)
        return INFINITY;
    double sides = (mask & 3u) == 3u ? 2.0 : 1.0;
    double area = area_m2 * sides;
    /* first guess: k photons at the object's mean density (right at once for about two
     * thirds of final-gather's secondary hits on the paper's scene, 1.4 queries on
     * average) */
    double r2 = area > 0.0 ? (double)k * area / ((double)available * M_PI) : 1.0;
    double lo = 0.0, hi = INFINITY; /* too few photons within lo, too many within hi */
    for (int tries = 0; tries < KNN_TRIES; tries++) {
        b->n = b->total = 0;
        b->radius2_m2 = r2;
        for (int pass = 0; pass < 2; pass++) {
            int side = pass == 0 ? seen_side : 1 - seen_side;
            if (!(mask >> side & 1u))
                continue;
            b->other_side = side != seen_side;
            photon_map_radius_in(map, dir, object, side, position, r2, knn_visit, b);
        }
        if (b->total < k) {
            lo = r2;
            r2 = isfinite(hi) ? sqrt(lo * hi)
                              : r2 * (b->total ? 2.0 * (double)k / (double)b->total : 16.0);
        } else if (b->total > KNN_CAP) {
            hi = r2;
            r2 = lo > 0.0 ? sqrt(lo * hi) : r2 * 0.5 * (double)KNN_CAP / (double)b->total;
        } else {
            for (size_t i = 0; i < b->n; i++)
                scratch[i] = b->e[i].d2;
            return knn_kth_smallest(scratch, b->n, k);
        }
        if (!(r2 > 0.0) || !isfinite(r2))
            break;
    }
    return NAN;
}
