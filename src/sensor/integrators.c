/* The table of integrators (integrator.h) and what the run asks of them. */
#include <string.h>

#include "core/rng.h"
#include "sensor/integrator.h"

/* The one table of integrators (their names: scene_integrator_names). */
static const render_integrator render_integrators[] = {
    {INTEGRATOR_PHOTON_MAP, render_photon_map_sample, true, 0},
    {INTEGRATOR_FINAL_GATHER, render_final_gather_sample, true, RNG_PURPOSE_GATHER},
    {INTEGRATOR_PATH, render_path_sample, false, RNG_PURPOSE_PATH},
};
#define RENDER_N_INTEGRATORS (sizeof render_integrators / sizeof render_integrators[0])

const render_integrator *render_integrator_find(thz_integrator id)
{
    for (size_t i = 0; i < RENDER_N_INTEGRATORS; i++)
        if (render_integrators[i].id == id)
            return &render_integrators[i];
    return NULL;
}

const char *render_integrator_name(thz_integrator integrator)
{
    return render_integrator_find(integrator) ? scene_integrator_names[integrator] : "unknown";
}

bool render_integrator_parse(const char *name, thz_integrator *out)
{
    for (size_t i = 0; i < RENDER_N_INTEGRATORS; i++)
        if (strcmp(scene_integrator_names[render_integrators[i].id], name) == 0) {
            *out = render_integrators[i].id;
            return true;
        }
    return false;
}

thz_status render_integrator_check(thz_integrator integrator, thz_error *err)
{
    const render_integrator *it = render_integrator_find(integrator);
    if (!it)
        return thz_error_set(err, THZ_ERR_INPUT, "unknown integrator %d", (int)integrator);
    return THZ_OK;
}

bool render_integrator_needs_photons(thz_integrator integrator)
{
    const render_integrator *it = render_integrator_find(integrator);
    return it ? it->needs_photons : true;
}

bool render_integrator_has_passes(thz_integrator integrator)
{
    const render_integrator *it = render_integrator_find(integrator);
    return it && it->purpose != 0;
}

uint32_t render_estimates_per_pass(const thz_scene *scene)
{
    switch (scene->render.integrator) {
    case INTEGRATOR_PATH:
        return scene->render.paths_per_sample > 0 ? scene->render.paths_per_sample : 1;
    case INTEGRATOR_FINAL_GATHER:
        return scene->render.gather_rays > 0 ? scene->render.gather_rays : 1;
    default:
        return 1;
    }
}

bool render_stratum(const render_context *ctx, const render_target *t, uint32_t j,
                    uint32_t crossings, sampling_stratum *out)
{
    uint32_t member = t->stratum % SAMPLING_STRATA_MAX;
    uint32_t members = t->n_strata - (t->stratum - member);
    if (members > SAMPLING_STRATA_MAX)
        members = SAMPLING_STRATA_MAX;
    if (members < 2)
        return false;
    /* the set's stream: numbered as estimate j of its first sample (samples of a pixel
     * are consecutive, J streams apart), under a purpose of its own */
    uint64_t first = t->rng_index - (uint64_t)member * t->n_est;
    uint64_t index = (first + j) * (RENDER_MAX_CROSSINGS + 1) + crossings;
    /* the set is drawn once by the thread for its members (at 4 samples a pixel, its
     * Philox blocks and permutation were 5 % of path's instructions drawn by each) */
    render_strata *keep = crossings == 0 && t->strata ? &t->strata[j] : NULL;
    if (keep && keep->key == index && keep->set.count == members) {
        *out = sampling_set_member(&keep->set, member);
        return true;
    }
    rng_stream rng;
    rng_init(&rng, ctx->seed, ctx->channel_index, RNG_PURPOSE_GATHER_STRATA, index);
    sampling_set set;
    sampling_set_draw(&rng, members, &set);
    if (keep) {
        keep->key = index;
        keep->set = set;
    }
    *out = sampling_set_member(&set, member);
    return true;
}
