/* Material recognition on a spectral cube against a truth map (docs/analysis.md):
 * spectral angle mapper, Mahalanobis distance, linear discriminant analysis, and the
 * matched filter and adaptive coherence estimator (ACE) detectors, each target against
 * the rest. Class statistics come from training pixels, a seeded split of each class;
 * the result is a class per pixel, the confusion matrix against the truth, accuracies,
 * and per class the ROC curve and its area (AUC) on the held-out pixels.
 *
 * The classes are the objects the truth map holds (its values >= 0), in ascending
 * order; pixels where the truth is negative (nothing hit) are left out everywhere.
 */
#ifndef THZ_ANALYSIS_CLASSIFY_H
#define THZ_ANALYSIS_CLASSIFY_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

typedef enum classify_method {
    CLASSIFY_SAM = 0,
    CLASSIFY_MAHALANOBIS,
    CLASSIFY_LDA,
    CLASSIFY_MATCHED_FILTER,
    CLASSIFY_ACE,
    CLASSIFY_METHOD_COUNT
} classify_method;

/* "sam", "mahalanobis", "lda", "matched-filter", "ace". */
const char *classify_method_name(classify_method m);
/* The method called `name`; -1 when none is. */
int classify_method_from_name(const char *name);

/* Points of each ROC curve (evenly spaced along the curve's sorted scores). */
enum { CLASSIFY_ROC_POINTS = 101 };

typedef struct classify_result {
    size_t n_classes;
    int32_t *class_object; /* per class: its object index (the truth value) */
    size_t pixels;
    int32_t *assigned;   /* per pixel: the object index of its class, -1 where the truth is -1 */
    uint8_t *train;      /* per pixel: 1 for a training pixel */
    uint64_t *confusion; /* [truth class * n_classes + assigned class], every pixel seen */
    uint64_t n_train, n_held_out;
    double accuracy;           /* trace / sum of confusion */
    double held_out_accuracy;  /* the same over the held-out pixels (NaN: none) */
    double *class_accuracy;    /* per class: its pixels assigned to it / its pixels */
    double *auc;               /* per class, one against the rest on held-out pixels (NaN:
                                  no held-out pixel of it or of the rest) */
    double *roc_fpr, *roc_tpr; /* [class * CLASSIFY_ROC_POINTS + i] */
} classify_result;

/* Classifies the pixels of `cube` (bands x pixels, band-sequential, e.g. brightness
 * temperatures in K) against `truth` (one value per pixel: an object index, or < 0).
 * `train_fraction` (0 < f < 1) of each class's pixels, at least one, train; which
 * ones is decided by `seed` alone. THZ_ERR_INPUT when no pixel has a truth >= 0 or a
 * value is not finite. */
thz_status classify_run(const float *cube, size_t bands, size_t pixels, const int32_t *truth,
                        classify_method method, double train_fraction, uint64_t seed,
                        classify_result *out, thz_error *err);

void classify_result_fini(classify_result *r);

/* Adds independent Gaussian noise of standard deviation sigma[band] to every value of
 * cube (bands x pixels), deterministic for `seed` (the noise of value (band, pixel)
 * depends on the seed, band and pixel alone). */
void classify_add_noise(float *cube, size_t bands, size_t pixels, const double *sigma,
                        uint64_t seed);

#endif
