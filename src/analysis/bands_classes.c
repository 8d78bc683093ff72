/* The classes' statistics from a band values' render (bands_values.c renders): which
 * object is which class (the targets and "background", or every object seen), each
 * pixel's class, the class means, their pixel covariance with the Monte Carlo variance
 * taken out, and each class's NETD (bands_values_internal.h).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "analysis/bands_values_internal.h"
#include "core/alloc.h"
#include "core/error.h"
#include "physics/planck.h"
#include "scene/scene.h"
#include "sensor/noise.h"

thz_status bands_assign_classes(const bands_setup *s, const thz_scene *scene, const int32_t *ids,
                                size_t pixels, int32_t *class_of, bool *is_class, bands_values *v,
                                thz_error *err)
{
    size_t n_obj = thz_scene_object_count(scene);
    uint64_t *seen = thz_calloc(n_obj, sizeof *seen);
    thz_status st = THZ_OK;
    if (!seen) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t p = 0; p < pixels; p++)
        if (ids[p] >= 0 && (size_t)ids[p] < n_obj)
            seen[ids[p]]++;
    size_t nc = 0;
    if (s->n_targets) {
        for (size_t o = 0; o < n_obj; o++)
            class_of[o] = -1;
        for (size_t t = 0; t < s->n_targets; t++) {
            if (!seen[s->targets[t]]) {
                thz_object_info oi;
                thz_scene_object(scene, (size_t)s->targets[t], &oi);
                st = thz_error_set(err, THZ_ERR_INPUT,
                                   "targets: the sensor sees no pixel of '%s' (the truth names "
                                   "the first surface a ray meets: a target behind a cover is "
                                   "the cover's pixels; name the cover, giving the part over "
                                   "the target an object of its own)",
                                   oi.name);
                goto done;
            }
            class_of[s->targets[t]] = (int32_t)nc++;
            is_class[s->targets[t]] = true;
        }
        bool background = false;
        for (size_t o = 0; o < n_obj; o++)
            background = background || (seen[o] && class_of[o] < 0);
        for (size_t o = 0; o < n_obj; o++)
            if (class_of[o] < 0)
                class_of[o] = background ? (int32_t)nc : -1;
        nc += background;
    } else {
        for (size_t o = 0; o < n_obj; o++) {
            class_of[o] = seen[o] ? (int32_t)nc++ : -1;
            is_class[o] = seen[o] > 0;
        }
    }
    v->n_classes = nc;
    v->class_names = thz_calloc(nc, sizeof *v->class_names);
    v->class_pixels = thz_calloc(nc, sizeof *v->class_pixels);
    if (!v->class_names || !v->class_pixels) {
        st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t o = 0; o < n_obj; o++) {
        int32_t k = class_of[o];
        if (k < 0 || v->class_names[k])
            continue;
        thz_object_info oi;
        thz_scene_object(scene, o, &oi);
        v->class_names[k] = thz_strdup(is_class[o] ? oi.name : "background");
        if (!v->class_names[k]) {
            st = thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
            goto done;
        }
    }
done:
    free(seen);
    return st;
}

void bands_pixel_classes(const bands_render *r, const int32_t *class_of, size_t n_obj,
                         size_t n_classes, int32_t *cls, uint64_t *count)
{
    memset(count, 0, n_classes * sizeof *count);
    for (size_t p = 0; p < r->pixels; p++) {
        cls[p] = r->ids[p] >= 0 && (size_t)r->ids[p] < n_obj ? class_of[r->ids[p]] : -1;
        if (cls[p] >= 0)
            count[cls[p]]++;
    }
}

void bands_class_means(const bands_render *r, const int32_t *cls, const uint64_t *count,
                       const bands_values *v, const double *fallback, double *mean)
{
    size_t n = v->n_candidates;
    memset(mean, 0, v->n_classes * n * sizeof *mean);
    for (size_t c = 0; c < n; c++)
        for (size_t p = 0; p < r->pixels; p++)
            if (cls[p] >= 0)
                mean[(size_t)cls[p] * n + c] += r->tb[c * r->pixels + p];
    for (size_t k = 0; k < v->n_classes; k++)
        for (size_t c = 0; c < n; c++)
            mean[k * n + c] = count[k] ? mean[k * n + c] / (double)count[k] : fallback[k * n + c];
}

void bands_pixel_covariance(const bands_render *r, const int32_t *cls, const bands_setup *s,
                            bands_values *v, double *x)
{
    size_t n = v->n_candidates, pixels = r->pixels;
    for (size_t p = 0; p < pixels; p++) {
        if (cls[p] < 0)
            continue;
        size_t k = (size_t)cls[p];
        for (size_t c = 0; c < n; c++)
            x[c] = r->tb[c * pixels + p] - v->mean[k * n + c];
        double *cov = v->cov + k * n * n;
        for (size_t a = 0; a < n; a++)
            for (size_t b = 0; b <= a; b++)
                cov[a * n + b] += x[a] * x[b];
    }
    for (size_t k = 0; k < v->n_classes; k++) {
        double *cov = v->cov + k * n * n;
        double d = v->class_pixels[k] > 1 ? (double)(v->class_pixels[k] - 1) : 1.0;
        for (size_t a = 0; a < n; a++)
            for (size_t b = 0; b <= a; b++) {
                cov[a * n + b] /= d;
                cov[b * n + a] = cov[a * n + b];
            }
    }
    /* Removing the Monte Carlo variance mc_c from the diagonal alone could leave a
     * matrix that is not positive semi-definite; scaling row and column c by
     * sqrt(1 - mc_c / var_c) instead (D C D, D >= 0 diagonal) keeps it so and keeps the
     * correlations. */
    for (size_t k = 0; k < v->n_classes; k++) {
        double *cov = v->cov + k * n * n;
        for (size_t c = 0; c < n; c++) {
            /* the radiance's standard error in K through dB/dT at the channel's centre
             * (the bands are narrow) */
            double nu = s->candidates_thz[c] * 1e12, mc = 0.0;
            for (size_t p = 0; p < pixels; p++)
                if (cls[p] == (int32_t)k) {
                    double t = r->tb[c * pixels + p];
                    double sd = t > 0.0 ? r->stderr_l[c * pixels + p] / planck_dbdt(nu, t) : 0.0;
                    mc += sd * sd;
                }
            mc /= (double)v->class_pixels[k];
            double var = cov[c * n + c];
            /* the pixels' errors are independent: the mean's variance is their mean / pixels;
             * a render without standard errors has the pixels' variance stand in (a bound) */
            v->mean_mc_var[k * n + c] = (r->has_stderr ? mc : var) / (double)v->class_pixels[k];
            x[c] = var > mc ? sqrt(1.0 - mc / var) : 0.0;
        }
        for (size_t a = 0; a < n; a++)
            for (size_t b = 0; b < n; b++)
                cov[a * n + b] *= x[a] * x[b];
        for (size_t c = 0; c < n; c++) {
            v->pixel_sd[k * n + c] = sqrt(cov[c * n + c]);
            cov[c * n + c] += v->netd_k[k * n + c] * v->netd_k[k * n + c];
        }
    }
}

void bands_class_netd(const thz_scene *scene, const bands_setup *s, bands_values *v)
{
    size_t n = v->n_candidates;
    for (size_t k = 0; k < v->n_classes; k++)
        for (size_t c = 0; c < n; c++)
            v->netd_k[k * n + c] = s->netd_from_sensor
                                       ? noise_netd_k(&scene->sensors[s->sensor].noise,
                                                      &scene->channels[c], c, v->mean[k * n + c])
                                       : s->netd_k[c];
}
