/* The scene's run settings: the `photons` block (photon phase) and the `render` block
 * (integrator and its sample counts). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "scene/load.h"

thz_status load_photons(load_ctx *ctx, const load_cursor *root)
{
    static const char *const keys[] = {"per_channel", "seed", "min_relative_power",
                                       "gather_min_photons", NULL};
    thz_photon_settings *p = &ctx->scene->photons;
    load_cursor c = load_key(root, "photons");
    if (!c.value)
        return THZ_OK;
    uint64_t k = 0;
    const load_range fraction = {0.0, 1.0, false, true}; /* 0: no cut-off */
    thz_status st = load_expect_object(ctx, &c, keys);
    p->per_channel_given = json_object_get(c.value, "per_channel") != NULL;
    if (st == THZ_OK)
        st = load_integer(ctx, &c, "per_channel", 1, (uint64_t)1 << 53, false, p->per_channel,
                          &p->per_channel);
    if (st == THZ_OK)
        st = load_integer(ctx, &c, "seed", 0, INT64_MAX, false, p->seed, &p->seed);
    if (st == THZ_OK)
        st = load_number(ctx, &c, "min_relative_power", fraction, false, p->min_relative_power,
                         &p->min_relative_power);
    if (st == THZ_OK)
        st = load_integer(ctx, &c, "gather_min_photons", 2, 1000000, false, p->gather_min_photons,
                          &k);
    if (st == THZ_OK)
        p->gather_min_photons = (uint32_t)k;
    return st;
}

thz_status load_render(load_ctx *ctx, const load_cursor *root)
{
    static const char *const keys[] = {"integrator",     "gather_rays", "paths_per_sample",
                                       "target_noise_k", "max_seconds", NULL};
    thz_render_settings *r = &ctx->scene->render;
    load_cursor c = load_key(root, "render");
    if (!c.value)
        return THZ_OK;
    size_t integrator = 0;
    uint64_t rays = 0, paths = 0;
    thz_status st = load_expect_object(ctx, &c, keys);
    if (st == THZ_OK)
        st = load_choice(ctx, &c, "integrator", scene_integrator_names, false, INTEGRATOR_PATH,
                         &integrator);
    if (st == THZ_OK)
        st = load_integer(ctx, &c, "gather_rays", 1, 1000000, false, r->gather_rays, &rays);
    if (st == THZ_OK)
        st = load_integer(ctx, &c, "paths_per_sample", 1, 1000000, false, r->paths_per_sample,
                          &paths);
    if (st == THZ_OK)
        st = load_number(ctx, &c, "target_noise_k", LOAD_POSITIVE, false, 0.0, &r->target_noise_k);
    if (st == THZ_OK)
        st = load_number(ctx, &c, "max_seconds", LOAD_POSITIVE, false, 0.0, &r->max_seconds);
    if (st != THZ_OK)
        return st;
    r->paths_per_sample_given = json_object_get(c.value, "paths_per_sample") != NULL;
    r->integrator = (thz_integrator)integrator; /* scene_integrator_names' index */
    r->gather_rays = (uint32_t)rays;
    r->paths_per_sample = (uint32_t)paths;
    return THZ_OK;
}
