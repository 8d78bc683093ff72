/* The per-channel state of the renderer (render.h's render_context): the channel
 * quadrature, and the optics and Planck radiance of every object at every node, which
 * depend only on the scene, the channel and the photon map, so one is built per channel
 * and read (never written) by every pass, sensor and thread.
 */
#ifndef THZ_SENSOR_RENDER_CONTEXT_H
#define THZ_SENSOR_RENDER_CONTEXT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "physics/channel.h"
#include "physics/optics.h"
#include "sensor/render.h"

/* Scenes with at most this many objects get final-gather's table of band means per pair
 * of objects (render_context.pair_mean). */
#define RENDER_PAIR_OBJECTS 256

/* What every sample of one channel needs, precomputed once: the channel quadrature for
 * the emission term's band mean, and the optics and Planck radiance of every object at
 * every node. Read-only while rendering. */
struct render_context {
    const thz_scene *scene;
    const accel *accel;
    const photon_map *map;
    photon_map_directory *dir; /* map's directory for the radius queries (NULL: none) */
    const thz_channel *channel;
    uint32_t channel_index;
    uint64_t seed;
    size_t k;                /* gather_min_photons */
    size_t k_secondary;      /* final-gather: photons of a secondary hit's k-nearest disk */
    channel_quadrature quad; /* nodes and normalised weights of g_c */
    double *planck;          /* [object * quad.n + node]: B_nu(T_object), W m^-2 sr^-1 Hz^-1 */
    optics_point *optics;    /* [object * quad.n + node] */
    optics_point *opt_fixed; /* [object]: the optics at any frequency where opt_const */
    bool *opt_const;         /* [object]: scene_object_optics_constant (render_optics_at) */
    double *alpha_per_m;     /* [node]: atmospheric attenuation, 1/m */
    double *emission_mean;   /* [object]: band mean of eps B when eps does not depend on the
                                angle (solids without an index, explicit eps); NAN for the
                                others */
    bool *scatters;          /* [object]: R > 0 somewhere, or a diffuse shell */
    bool *mirror;            /* [object]: specular reflection with R > 0 somewhere (a mirror
                                of R = 0 reflects nothing: render_mirror follows no branch) */
    double *lookup_q;        /* final-gather, [object]: the probability that a gather ray
                                ending there looks up its photons (RENDER_GATHER_LOOKUP_FULL;
                                0 where nothing scatters) */
    double *tbar;            /* [object * quad.n + node]: T-bar of diffuse shells, else 0 */
    double *rbar;            /* [object * quad.n + node]: R-bar */
    brdf_lobe *lobes;        /* [object * quad.n + node]: the lobe at the node (its optics
                                point is optics[] there, means cached) */
    double *ward_scale;      /* [object * quad.n + node]: lobes[].scale and .comp_norm, */
    double *ward_comp;       /* as tables for render_lobe_at's interpolation */
    bool atmosphere;         /* some node has alpha > 0 */
    double t0_k;             /* reference temperature T0, K: path's, or the photon map's */
    double b0_mean;          /* band mean of B(T0) */
    double *b0;              /* [node] B_nu(T0) */
    double *source_mean;     /* [object] band mean of eps B - A B0 for solids without an
                                index; NAN for the others (angle-dependent) */
    bool guided;             /* final-gather: the photon guide may steer gather rays */
    bool deviation;          /* photon-map, final-gather: the map holds L - B(T0), T0 > 0,
                                so every source term is eps B - A B0 (escapes, back faces,
                                the air: minus B0) and the sample adds B0 back */
    double *pair_mean;       /* final-gather, [x * n_objects + y]: the band mean of
                                R_x (eps_y B_y - A_y B0) for solid y (else NAN), what a
                                reflected gather ray from x adds at y without shells or
                                air between; NULL beyond RENDER_PAIR_OBJECTS objects */
    bool emitting;           /* emitting atmosphere (docs/atmosphere.md) */
    bool air_terms;          /* render_air contributes: emitting, or deviation */
    double *air_planck;      /* air_terms: [node] B_nu(T_air), 0 for non-emitting air */
    double *bg_planck;       /* air_terms: [node] escape radiance B_nu(T_background), or 0 */
    const struct render_integrator *integrator; /* the scene's (integrator.h) */
};

#endif
