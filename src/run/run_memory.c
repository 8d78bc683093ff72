/* The memory a run needs, estimated before it starts, and the refusal of a run that
 * would not fit (run.h: run_memory). */
#include <math.h>
#include <stdio.h>

#include "core/alloc.h"
#include "core/threads.h"
#include "photon/phase.h"
#include "photon/photon_map.h"
#include "run/run.h"
#include "sensor/images.h"
#include "sensor/measure.h"
#include "sensor/render.h"

/* The photons per channel whose maps would fit in limit beside the rest of the run (held:
 * what the process holds, or has mapped, already): the maps' bytes grow in proportion to
 * the photons (records per photon, the build's scratch a fixed share of them), so
 * per_channel scaled by the room over the maps' bytes, less 3 % (the process's own
 * memory, in the room, moves a little from run to run), rounded down to two significant
 * digits; 0 if none fit. */
static uint64_t run_photons_that_fit(uint64_t per_channel, const run_memory *need, uint64_t held,
                                     double limit)
{
    double room = limit - (double)need->image_bytes - (double)held;
    if (!(room > 0.0) || need->photon_bytes == 0)
        return 0;
    double fit = 0.97 * (double)per_channel * room / (double)need->photon_bytes;
    if (!(fit >= 1.0))
        return 0;
    double unit = 1.0;
    while (fit >= 100.0 * unit)
        unit *= 10.0;
    return (uint64_t)(floor(fit / unit) * unit);
}

/* What to lower, into remedy: the larger part of the run (what the process holds decides
 * for the scene's objects), with the photons that would fit beside `held` in `limit`. */
static void run_memory_remedy(const thz_scene *scene, const run_memory *need, uint64_t held,
                              double limit, char *remedy, size_t size)
{
    if (need->held_bytes > need->photon_bytes && need->held_bytes > need->image_bytes) {
        size_t big = 0; /* the object of most triangles */
        for (size_t o = 1; o < scene->n_objects; o++)
            if (scene->objects[o].mesh.n_triangles > scene->objects[big].mesh.n_triangles)
                big = o;
        snprintf(remedy, size, "lower objects[%zu].shape (%zu triangles) or the number of objects",
                 big, scene->n_objects ? scene->objects[big].mesh.n_triangles : (size_t)0);
    } else if (need->photon_bytes >= need->image_bytes && need->map_photons > 0) {
        /* render: the scene's photons.per_channel does not make the map it reads */
        uint64_t fit = run_photons_that_fit(need->map_photons, need, held, limit);
        char most[64] = "";
        if (fit > 0)
            snprintf(most, sizeof most, "; at most about %llu fit", (unsigned long long)fit);
        snprintf(remedy, size,
                 "render from a map of fewer photons (this one has %llu per channel, read a "
                 "channel at a time%s)",
                 (unsigned long long)need->map_photons, most);
    } else if (need->photon_bytes >= need->image_bytes) {
        uint64_t fit = run_photons_that_fit(scene->photons.per_channel, need, held, limit);
        char most[64] = "";
        if (fit > 0)
            snprintf(most, sizeof most, "; at most about %llu fit", (unsigned long long)fit);
        /* the scene key only: batch and Python have no --photons (simulate adds it) */
        snprintf(remedy, size, "lower photons.per_channel (now %llu%s)",
                 (unsigned long long)scene->photons.per_channel, most);
    } else {
        size_t big = 0;
        for (size_t s = 1; s < scene->n_sensors; s++)
            if ((uint64_t)scene->sensors[s].columns * scene->sensors[s].rows >
                (uint64_t)scene->sensors[big].columns * scene->sensors[big].rows)
                big = s;
        /* the images of every sensor together: the largest alone may not be the cause */
        snprintf(remedy, size, "lower sensors[%zu].resolution%s", big,
                 scene->n_sensors > 1 ? " (or the number of sensors)" : "");
    }
}

/* The ulimit -v (KiB) to suggest for a run needing `need` bytes of address space: its 90 %
 * rule, 16 MiB to spare, in 4 MiB steps. The address space mapped before the check moves
 * from run to run by a few KiB (the environment, the libraries' placement): a limit of
 * exactly the need refused a later run by 84 KiB (tests/cli/test_address_space_limit.sh
 * under ctest -j2, 2026-12-08). Not more: a limit with room for another thread's stack
 * and 64 MiB arena lets thz_threads_prepare start it, and the run then needs that too
 * (a render refused at 250000 KiB on 1 thread, told 360448, was refused there on 2). */
static double run_memory_limit_kib(double need)
{
    const double step = 4096.0; /* KiB */
    return ceil((need / 0.9 / 1024.0 + 16384.0) / step) * step;
}

thz_status run_check_memory(const thz_scene *scene, const run_memory *need, thz_error *err)
{
    const char *path = scene->path ? scene->path : "the scene";
    char remedy[192];
    /* Under ulimit -v the address space counts, not what is resident: at the check a render
     * had 18 MB resident and 291 MB mapped (Embree's pool, thread stacks and arenas), and
     * a map that passed the resident check then failed to load. */
    double as_limit = 0.9 * (double)need->address_limit_bytes;
    double as_need =
        (double)need->mapped_bytes + (double)need->photon_bytes + (double)need->image_bytes;
    if (need->address_limit_bytes > 0 && as_need > as_limit) {
        const double mib = 1024.0 * 1024.0;
        run_memory_remedy(scene, need, need->mapped_bytes, as_limit, remedy, sizeof remedy);
        return thz_error_set(
            err, THZ_ERR_LIMIT,
            "%s: the run would need %.0f MiB of address space (photon maps %.0f MiB, images "
            "and tables %.0f MiB, mapped already %.0f MiB: the program and its libraries, the "
            "scene, the ray-casting structure, the threads' stacks and malloc arenas) but "
            "ulimit -v limits this process to %llu KiB (%.0f MiB), of which a run may take 90 "
            "%% (ulimit -v %.0f or more would do); %s",
            path, as_need / mib, (double)need->photon_bytes / mib, (double)need->image_bytes / mib,
            (double)need->mapped_bytes / mib,
            (unsigned long long)(need->address_limit_bytes / 1024),
            (double)need->address_limit_bytes / mib, run_memory_limit_kib(as_need), remedy);
    }
    if (need->available_bytes == 0)
        return THZ_OK; /* unknown: let the allocations decide */
    double limit = 0.9 * (double)need->available_bytes;
    if ((double)need->total_bytes <= limit)
        return THZ_OK;
    double gib = 1024.0 * 1024.0 * 1024.0;
    run_memory_remedy(scene, need, need->held_bytes, limit, remedy, sizeof remedy);
    return thz_error_set(err, THZ_ERR_LIMIT,
                         "%s: the run would need %.2f GiB of memory (photon maps %.2f GiB, "
                         "images and tables %.2f GiB, the scene as loaded %.2f GiB) but this "
                         "process may have %.2f GiB (the machine's memory, or less under ulimit "
                         "-v or a cgroup limit); %s",
                         path, (double)need->total_bytes / gib, (double)need->photon_bytes / gib,
                         (double)need->image_bytes / gib, (double)need->held_bytes / gib,
                         (double)need->available_bytes / gib, remedy);
}

thz_status run_check_scene_memory(const thz_scene *scene, thz_error *err)
{
    uint64_t have = thz_memory_limit_bytes();
    for (size_t s = 0; s < scene->n_sensors && have > 0; s++) {
        const thz_sensor *sn = &scene->sensors[s];
        uint64_t need = sensor_images_bytes(sn->columns, sn->rows, scene->n_channels);
        if ((double)need > 0.9 * (double)have) /* as run_check_memory */
            return thz_error_set(err, THZ_ERR_LIMIT,
                                 "%s: sensors[%zu].resolution: the images of %u x %u pixels in "
                                 "%zu channels need %.1f GiB, more than the %.1f GiB this "
                                 "process may have (the machine's memory, or less under ulimit "
                                 "-v or a cgroup limit); lower 'resolution' (or the "
                                 "number of channels)",
                                 scene->path, s, sn->columns, sn->rows, scene->n_channels,
                                 (double)need / 1073741824.0, (double)have / 1073741824.0);
    }
    return THZ_OK;
}

static uint64_t run_image_bytes(const run_state *rs)
{
    uint64_t total = 0;
    /* the pixel statistics of the channel being rendered: mean and m2, and final-gather's
     * photon batches and disk variance (render_accum) */
    uint64_t per_pixel =
        2u +
        (rs->scene->render.integrator == INTEGRATOR_FINAL_GATHER ? PHOTON_MAP_BATCHES + 1u : 0u);
    for (size_t i = 0; i < rs->n_selected; i++) {
        const thz_sensor *s = &rs->scene->sensors[rs->selected[i]];
        total += sensor_images_bytes(s->columns, s->rows, rs->scene->n_channels);
        if (sensor_has_model(s)) /* measured radiance and Tb */
            total += 2u * sizeof(float) * s->columns * s->rows * rs->scene->n_channels;
        total += (uint64_t)s->columns * s->rows * per_pixel * sizeof(double);
        /* the noise figures' copy of a channel's pixels (run_noise.c: object and value,
         * then the values grouped) */
        total += (uint64_t)s->columns * s->rows * (sizeof(int32_t) + 2u * sizeof(double));
    }
    return total + render_context_bytes(rs->scene);
}

/* a + b, or UINT64_MAX when the sum does not fit (estimates of absurd runs saturate, so
 * that they are refused instead of wrapping to a small number). */
static uint64_t run_add_bytes(uint64_t a, uint64_t b)
{
    return a > UINT64_MAX - b ? UINT64_MAX : a + b;
}

thz_status run_photon_map_bytes(const thz_scene *scene, const accel *acc, size_t only,
                                bool keep_all, emission_reach *reach, uint64_t *out, thz_error *err)
{
    uint64_t sum = 0, max = 0;
    for (size_t c = 0; c < scene->n_channels; c++) {
        if (only != SIZE_MAX && c != only)
            continue;
        uint64_t b = 0;
        thz_status st =
            photon_phase_estimate_bytes(scene, acc, c, run_photon_t0_k(scene, c), reach, &b, err);
        if (st != THZ_OK)
            return st;
        sum = run_add_bytes(sum, b);
        max = b > max ? b : max;
    }
    /* While a map is built: kept maps (the one being built among them) and the build's
     * scratch (3/8 as large), else the map in the pool's spare array (up to a quarter
     * larger: phase_fire.c) and the scratch. */
    uint64_t scratch =
        photon_map_scratch_records(max / sizeof(photon_record)) * (uint64_t)sizeof(photon_record);
    *out = keep_all ? run_add_bytes(sum, scratch)
                    : run_add_bytes(run_add_bytes(max, max / 4), scratch);
    return THZ_OK;
}

/* The address space mapped now, and what the threads of rs's runs still to start will
 * map (thz_thread_address_bytes each). */
static uint64_t run_mapped_bytes(const run_state *rs)
{
    uint64_t mapped = thz_address_space_bytes();
    int team = thz_threads_or_all(rs->opt->threads), running = thz_threads_running();
    uint64_t more = team > running ? (uint64_t)(team - running) : 0;
    uint64_t per = thz_thread_address_bytes();
    return more > 0 && per > (UINT64_MAX - mapped) / more ? UINT64_MAX : mapped + more * per;
}

thz_status run_check_run_memory(run_state *rs, bool photons, uint64_t map_bytes,
                                uint64_t map_photons, thz_error *err)
{
    run_memory need = {.image_bytes = run_image_bytes(rs),
                       .photon_bytes = map_bytes,
                       .held_bytes = thz_process_memory_bytes(),
                       .available_bytes = thz_memory_limit_bytes(),
                       .map_photons = map_bytes > 0 ? map_photons : 0,
                       .mapped_bytes = run_mapped_bytes(rs),
                       .address_limit_bytes = thz_address_space_limit_bytes()};
    if (photons) {
        thz_status st =
            run_photon_map_bytes(rs->scene, rs->accel, SIZE_MAX, rs->opt->keep_photon_maps,
                                 &rs->reach, &need.photon_bytes, err);
        if (st != THZ_OK)
            return st;
    }
    need.total_bytes =
        run_add_bytes(run_add_bytes(need.photon_bytes, need.image_bytes), need.held_bytes);
    rs->memory_bytes = need.total_bytes;
    return run_check_memory(rs->scene, &need, err);
}
