/* Band values from the scene itself (docs/analysis.md "thzmap bands"): the scene is
 * rendered with the candidate channels as its channels (path integrator, converged
 * radiance through covers and air), once as it is and once per nuisance changed
 * (each target's temperature alone, the surroundings' and the air's temperature, the air's
 * humidity, the shells' thickness, the viewing angle); each class's pixels come from
 * each render's object_id truth. The result is each
 * class's mean brightness temperature per candidate and its covariance over the
 * candidates: pixel spread (Monte Carlo noise removed) + nuisances + the sensor's NETD.
 */
#ifndef THZ_ANALYSIS_BANDS_VALUES_H
#define THZ_ANALYSIS_BANDS_VALUES_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "thzmap/thzmap.h"

typedef struct bands_setup {
    const char *scene_path;
    const char *root;             /* NULL, or the directory its files are confined to */
    const double *candidates_thz; /* n_candidates centres (repeated once per width) */
    const double *widths;         /* n_candidates relative widths (FWHM / centre) */
    size_t n_candidates;
    size_t sensor;
    const long *targets; /* object indices; n_targets 0: every object seen is a class */
    size_t n_targets;
    double *netd_k;        /* per candidate: the sensor's NETD, K (thzmap/analysis.h) */
    bool netd_from_sensor; /* a radiometer: netd_k becomes the sensor's NETD of each
                              candidate in the scene with the candidates as channels */
    double target_range_k, ambient_range_k, humidity_range;
    double thickness_range, angle_range_deg;
    uint32_t paths_per_sample;
    uint64_t seed;
} bands_setup;

typedef struct bands_values {
    size_t n_candidates, n_classes;
    char **class_names;     /* per class: the object's name, or "background" */
    uint64_t *class_pixels; /* per class */
    double *mean;           /* [class * n + c]: mean Tb of the class's pixels, K (nominal) */
    double *cov;            /* [class * n^2 + c * n + c']: K^2 */
    double *pixel_sd;       /* [class * n + c]: pixel spread (MC removed), K */
    double *nuisance_sd;    /* [class * n + c]: all nuisances together, K */
    double *mean_mc_var;    /* [class * n + c]: variance of the mean's Monte Carlo error, K^2 */
    double *netd_k;         /* [class * n + c]: the sensor's NETD at the class's mean Tb, K */
    bool spread_is_noise;   /* the render estimated no standard error (one path of one
                               sample per pixel): cov's pixel spread holds its noise */
    bool humidity_varied, air_temperature_varied, thickness_varied, angle_varied;
    size_t renders;
    uint32_t coarse_paths; /* paths per sample of the nuisances' renders (1 sample per pixel) */
    double seconds;
} bands_values;

/* Renders and reduces as above. Progress and cancellation through ctx. */
thz_status bands_values_compute(thz_context *ctx, const bands_setup *setup, bands_values *out,
                                thz_error *err);
void bands_values_fini(bands_values *v);

#endif
