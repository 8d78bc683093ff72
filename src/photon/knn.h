/* The k-nearest photons of one object by radius queries (photon_map.h): the photons
 * within a radius, with their squared distances, are collected in a bounded buffer, and
 * the radius is bisected (in r^2, geometrically) until the buffer holds at least k and
 * at most its capacity. The k-th smallest distance in the buffer is then the k-th
 * nearest photon's, and the photons strictly inside it are those of the buffer below
 * it: one or two cheap radius queries instead of a k-nearest traversal and a radius
 * query (about half of final-gather's time). The result is that of
 * photon_map_kth_distance2 exactly, whatever the first guess.
 */
#ifndef THZ_PHOTON_KNN_H
#define THZ_PHOTON_KNN_H

#include <stddef.h>
#include <stdint.h>

#include "core/vec3.h"
#include "photon/photon_map.h"

#define KNN_CAP 2048

/* Radius bisections before knn_collect gives up (NAN). */
#define KNN_TRIES 48

typedef struct knn_entry {
    double d2;
    const photon_record *p;
    int other_side; /* the side not seen (diffuse shells: transmitted photons) */
} knn_entry;

/* Large (about 48 KiB): callers keep it on their stack, one per thread. */
typedef struct knn_buffer {
    knn_entry e[KNN_CAP];
    size_t n;     /* entries stored (<= KNN_CAP) */
    size_t total; /* photons within the radius, stored or not */
    double radius2_m2;
    int other_side;
} knn_buffer;

/* Fills b with the photons of `object` (sides in `mask`, seen side first, in the order a
 * radius query visits them) within the k-th nearest photon's distance or somewhat
 * beyond, and returns that squared distance (m^2); NAN when the search does not settle
 * (the caller falls back to photon_map_kth_distance2), INFINITY when the object holds
 * fewer than k photons. dir is map's directory or NULL. area_m2 is the object's area of
 * one side (the first guess is k photons at its mean density); scratch holds KNN_CAP
 * doubles. Allocates nothing. */
double knn_collect(const photon_map *map, const photon_map_directory *dir, uint32_t object,
                   double area_m2, int seen_side, unsigned mask, vec3 position, size_t k,
                   knn_buffer *b, double *scratch);

#endif
