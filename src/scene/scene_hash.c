/* Fingerprints of the parts of a scene that determine its photon maps. */
#include "scene/scene_hash.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"

#define HASH_PRIME 0x100000001b3ull
#define HASH_OFFSET 0xcbf29ce484222325ull

static uint64_t hash_word(uint64_t h, uint64_t w)
{
    for (int i = 0; i < 8; i++) {
        h ^= (w >> (8 * i)) & 0xffu;
        h *= HASH_PRIME;
    }
    return h;
}

static uint64_t hash_double(uint64_t h, double x)
{
    uint64_t w;
    memcpy(&w, &x, sizeof w);
    return hash_word(h, w);
}

/* n 32-bit words (indices or float bit patterns) after their count, each least
 * significant byte first whatever the host's byte order, so the hashes stored in
 * photon-map files stay comparable. */
static uint64_t hash_words32(uint64_t h, const void *p, size_t n)
{
    const unsigned char *bytes = p;
    h = hash_word(h, n);
    for (size_t i = 0; i < n; i++) {
        uint32_t w;
        memcpy(&w, bytes + 4 * i, sizeof w);
        for (int k = 0; k < 4; k++) {
            h ^= (w >> (8 * k)) & 0xffu;
            h *= HASH_PRIME;
        }
    }
    return h;
}

static uint64_t hash_spectrum(uint64_t h, const thz_spectrum *s)
{
    h = hash_word(h, s->n);
    for (size_t i = 0; i < s->n; i++) {
        if (s->freq_hz)
            h = hash_double(h, s->freq_hz[i]);
        h = hash_double(h, s->value[i]);
    }
    return h;
}

/* A complex index (material_index.h), which the material's spectra do not hold: n and k
 * at the table's frequencies and at 17 points across each channel's band (its support
 * at 4 sigma, inside the 2 FWHM where the loader checks the index), which a change of
 * any table value or model parameter that the bands can see moves. */
static uint64_t hash_index(uint64_t h, const thz_scene *scene, const material_index *idx)
{
    const double *table_hz = NULL;
    size_t n_table = material_index_table_hz(idx, &table_hz);
    h = hash_word(h, n_table);
    double n, k;
    for (size_t i = 0; i < n_table; i++)
        if (material_index_at(idx, table_hz[i], &n, &k)) {
            h = hash_double(h, n);
            h = hash_double(h, k);
        }
    for (size_t c = 0; c < scene->n_channels; c++) {
        double lo, hi;
        channel_support_hz(&scene->channels[c], 4.0, &lo, &hi);
        if (!(lo > 0.0))
            lo = hi / 1024.0;
        for (int j = 0; j <= 16; j++)
            if (material_index_at(idx, lo + (hi - lo) * j / 16.0, &n, &k)) {
                h = hash_double(h, n);
                h = hash_double(h, k);
            }
    }
    return h;
}

/* splitmix64's finaliser: spreads the last bytes over the whole word. */
static uint64_t hash_finish(uint64_t h)
{
    h ^= h >> 30;
    h *= 0xbf58476d1ce4e5b9ull;
    h ^= h >> 27;
    h *= 0x94d049bb133111ebull;
    h ^= h >> 31;
    return h;
}

struct scene_hash_memo {
    atomic_bool done;
    _Atomic uint64_t geometry;
};

struct scene_hash_memo *scene_hash_memo_create(void)
{
    struct scene_hash_memo *m = thz_calloc(1, sizeof *m);
    if (m) {
        atomic_init(&m->done, false);
        atomic_init(&m->geometry, 0);
    }
    return m;
}

void scene_hash_memo_destroy(struct scene_hash_memo *memo)
{
    free(memo);
}

static uint64_t hash_geometry(const thz_scene *scene)
{
    struct scene_hash_memo *m = scene->hash_memo;
    if (m && atomic_load_explicit(&m->done, memory_order_acquire))
        return atomic_load_explicit(&m->geometry, memory_order_relaxed);
    uint64_t g = hash_word(HASH_OFFSET, scene->n_objects);
    for (size_t i = 0; i < scene->n_objects; i++) {
        const thz_object *obj = &scene->objects[i];
        g = hash_word(g, (uint64_t)obj->type);
        g = hash_word(g, scene_object_two_sided(obj) ? 1u : 0u);
        g = hash_double(g, obj->thickness_m);
        g = hash_words32(g, obj->mesh.positions, 3 * obj->mesh.n_vertices);
        g = hash_words32(g, obj->mesh.indices, 3 * obj->mesh.n_triangles);
    }
    if (m) {
        atomic_store_explicit(&m->geometry, g, memory_order_relaxed);
        atomic_store_explicit(&m->done, true, memory_order_release);
    }
    return g;
}

void scene_hash_compute(const thz_scene *scene, scene_hash *out)
{
    uint64_t g = hash_geometry(scene), o = HASH_OFFSET, c = HASH_OFFSET;
    o = hash_word(o, scene->n_objects);
    for (size_t i = 0; i < scene->n_objects; i++) {
        const thz_object *obj = &scene->objects[i];
        o = hash_word(o, obj->material);
        o = hash_double(o, obj->temperature_k);
    }
    o = hash_word(o, scene->n_materials);
    for (size_t i = 0; i < scene->n_materials; i++) {
        const thz_material *m = &scene->materials[i];
        o = hash_spectrum(o, &m->reflectivity);
        o = hash_spectrum(o, &m->attenuation_per_m);
        o = hash_spectrum(o, &m->emissivity);
        o = hash_word(o, (uint64_t)m->transmission);
        if (m->reflection != REFLECTION_DIFFUSE) { /* only then: older hashes stay valid */
            o = hash_word(o, (uint64_t)m->reflection);
            o = hash_double(o, m->ward_alpha[0]);
            o = hash_double(o, m->ward_alpha[1]);
        }
        if (m->index) /* only then, as the lobe */
            o = hash_index(o, scene, m->index);
    }
    const thz_atmosphere *atm = &scene->atmosphere;
    o = hash_word(o, (uint64_t)atm->model);
    o = hash_spectrum(o, &atm->attenuation_per_m);
    o = hash_word(o, atm->has_air ? 1u : 0u);
    if (atm->has_air) {
        o = hash_double(o, atm->air.temperature_k);
        o = hash_double(o, atm->air.pressure_hpa);
        o = hash_double(o, atm->air.h2o_pressure_hpa);
    }
    /* The line-by-line models' alpha over the bands, as prepared: covers the catalogues
     * and switches without knowing them. */
    o = hash_word(o, atm->n_tables);
    for (size_t i = 0; i < atm->n_tables; i++) {
        const atm_band_table *t = &atm->tables[i];
        o = hash_double(o, t->lo_hz);
        o = hash_double(o, t->step_hz);
        o = hash_word(o, t->n);
        for (size_t k = 0; k < t->n; k++)
            o = hash_double(o, t->alpha_per_m[k]);
    }
    o = hash_word(o, atm->emitting ? 1u : 0u);
    if (atm->emitting) {
        o = hash_double(o, atm->background_temperature_k);
        /* constant/table models have no air state: their emitting air's temperature */
        o = hash_double(o, atm->air.temperature_k);
    }
    o = hash_word(o, atm->has_extent ? 1u : 0u);
    if (atm->has_extent)
        for (int k = 0; k < 3; k++) {
            o = hash_double(o, atm->extent_min_m[k]);
            o = hash_double(o, atm->extent_max_m[k]);
        }
    c = hash_word(c, scene->n_channels);
    for (size_t i = 0; i < scene->n_channels; i++) {
        c = hash_double(c, scene->channels[i].center_hz);
        c = hash_double(c, scene->channels[i].relative_width);
        const thz_channel *ch = &scene->channels[i];
        for (size_t k = 0; k < ch->n_response; k++) { /* nothing for a Gaussian: as before */
            c = hash_double(c, ch->response_hz[k]);
            c = hash_double(c, ch->response_weight[k]);
        }
    }
    out->geometry = hash_finish(g);
    out->optics = hash_finish(o);
    out->channels = hash_finish(c);
}

thz_status scene_hash_fit(const scene_hash *made, uint64_t n_objects, uint64_t n_channels,
                          const thz_scene *scene, const char *maps, const char *remedy,
                          thz_error *err)
{
    const char *name = scene->path ? scene->path : "this scene";
    scene_hash h;
    scene_hash_compute(scene, &h);
    if (made->geometry != h.geometry || n_objects != scene->n_objects)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s was made from another scene geometry (objects or meshes differ "
                             "from %s); %s",
                             maps, name, remedy);
    if (n_channels != scene->n_channels)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s was made from another channel set (%llu channels; %s has %zu); %s",
                             maps, (unsigned long long)n_channels, name, scene->n_channels, remedy);
    if (made->channels != h.channels)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s was made from another channel set (frequencies, widths or "
                             "responses differ from %s); %s",
                             maps, name, remedy);
    /* The sensors are not in the fingerprint, but an emitting air's default temperature
     * and background are the enclosure's around them: a user who only moved the camera
     * into another room is told why. */
    bool air = scene->atmosphere.emitting && scene->atmosphere.model != ATM_NONE;
    if (made->optics != h.optics)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "%s was made from another scene (materials, temperatures or "
                             "atmosphere differ from %s%s); %s",
                             maps, name,
                             air ? "; the air's temperature and background, unless given, are "
                                   "the enclosure's around the sensors, which a sensor moved "
                                   "into another enclosure changes"
                                 : "",
                             remedy);
    return THZ_OK;
}

uint64_t scene_hash_run(const thz_scene *scene, bool render)
{
    scene_hash parts;
    scene_hash_compute(scene, &parts);
    uint64_t h = hash_word(HASH_OFFSET, parts.geometry);
    h = hash_word(h, parts.optics);
    h = hash_word(h, parts.channels);
    h = hash_word(h, scene->n_sensors);
    for (size_t i = 0; i < scene->n_sensors; i++) {
        const thz_sensor *s = &scene->sensors[i];
        for (int k = 0; k < 3; k++) {
            h = hash_double(h, s->position_m[k]);
            h = hash_double(h, s->direction[k]);
            h = hash_double(h, s->up[k]);
        }
        h = hash_double(h, s->fov_deg);
        h = hash_word(h, s->columns);
        h = hash_word(h, s->rows);
        h = hash_double(h, s->aperture_m2);
        h = hash_word(h, s->oversampling);
        h = hash_double(h, s->normalize_to_k);
        h = hash_double(h, s->aperture_diameter_m);
        h = hash_word(h, (uint64_t)s->psf);
        h = hash_double(h, s->psf_fwhm_deg);
    }
    /* not the photon count and seed: a map loaded for render sets them on the lead alone
     * (the members receive its records), and the photon phase checks them itself */
    h = hash_double(h, scene->photons.min_relative_power);
    h = hash_word(h, scene->photons.gather_min_photons);
    if (render) {
        h = hash_word(h, (uint64_t)scene->render.integrator);
        h = hash_word(h, scene->render.gather_rays);
        h = hash_word(h, scene->render.paths_per_sample);
    }
    return hash_finish(h);
}
