/* What the files of the band values share (bands_values.h says what they compute):
 * bands_values.c renders the scene's variants and adds up the nuisances;
 * bands_variants.c writes each variant's scene text (a nuisance changed, the candidates
 * as channels); bands_classes.c turns a render into the classes' statistics (which
 * object is which class, class means, pixel covariance, NETD). Nothing here is public.
 */
#ifndef THZ_ANALYSIS_BANDS_VALUES_INTERNAL_H
#define THZ_ANALYSIS_BANDS_VALUES_INTERNAL_H

#include <jansson.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "analysis/bands_values.h"

/* ---- bands_variants.c: the scene texts of the variants ---- */

/* The scene's JSON with the nuisance `what` changed: 0 nominal, 1 one target's
 * temperature + range (one variant per target), 2 the other objects' and the air's
 * temperature + range, 3 the humidity x (1 - range), 4 every shell's thickness
 * x (1 + range), 5 the sensor turned by the angle range. Channels and render settings
 * replaced in every variant. */
enum {
    VAR_NOMINAL = 0,
    VAR_TARGETS,
    VAR_AMBIENT,
    VAR_HUMIDITY,
    VAR_THICKNESS,
    VAR_ANGLE,
    VAR_COUNT
};

/* The nuisances' renders are coarse: one sample per pixel and a quarter of the paths
 * (at least one), against a coarse nominal render with the same seed. A class mean's
 * change is smooth over its pixels and the common seed keeps the Monte Carlo noise out
 * of the difference, so it needs far fewer samples than the pixel statistics do. */
uint32_t bands_coarse_paths(uint32_t paths);
/* The scene text of a variant (what, and for VAR_TARGETS the one object `target` whose
 * temperature is raised); *changed counts the values it changes. air_t_k: the nominal
 * air's temperature, K (NaN: none). */
char *bands_variant_text(const json_t *root, const bands_setup *s, const bool *is_class, int what,
                         size_t target, double air_t_k, bool coarse, int *changed);

/* ---- bands_classes.c: the classes' statistics from a render ---- */

/* One render of a variant: its Tb cube and radiance standard error (copied), its
 * object_id truth (a turned sensor sees the classes at other pixels), and the air's
 * temperature it used (K, NaN: its air has none). */
typedef struct bands_render {
    float *tb, *stderr_l;
    int32_t *ids;
    size_t pixels;
    double air_t_k;
    bool has_stderr; /* false: one sample of one path per pixel estimates none */
} bands_render;

/* The class of each object (class_of, n_obj entries, -1: none) from the nominal
 * render's truth: targets (in order) and "background", or every object seen. */
thz_status bands_assign_classes(const bands_setup *s, const thz_scene *scene, const int32_t *ids,
                                size_t pixels, int32_t *class_of, bool *is_class, bands_values *v,
                                thz_error *err);
/* The class of each pixel of render r (cls, r->pixels entries, -1: none) and each
 * class's pixel count. */
void bands_pixel_classes(const bands_render *r, const int32_t *class_of, size_t n_obj,
                         size_t n_classes, int32_t *cls, uint64_t *count);
/* Class means of a render's Tb into mean[class * n + c]; a class without pixels (a
 * turned sensor may lose one) takes `fallback`'s mean, i.e. no change. */
void bands_class_means(const bands_render *r, const int32_t *cls, const uint64_t *count,
                       const bands_values *v, const double *fallback, double *mean);
/* The pixel covariance of each class about its mean, less the Monte Carlo variance of
 * its pixels on the diagonal (floored at 0), plus its NETD^2 on the diagonal. */
void bands_pixel_covariance(const bands_render *r, const int32_t *cls, const bands_setup *s,
                            bands_values *v, double *x);
/* The NETD of each class and candidate: the radiometer's at the class's mean Tb (its
 * noise grows with the Tb it measures, scene-format.md "noise"), else the candidate's. */
void bands_class_netd(const thz_scene *scene, const bands_setup *s, bands_values *v);

#endif
