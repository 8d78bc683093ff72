/* The photon phase's statistics: see photon_stats.h. */
#include "photon/photon_stats.h"

#include <string.h>

#include "photon/trace.h"

void photon_stats_init(photon_stats *s)
{
    memset(s, 0, sizeof *s);
}

void photon_stats_add(photon_stats *s, const trace_counters *c, uint64_t stored)
{
    s->fired += c->photons;
    s->stored += stored;
    s->hits += c->hits;
    s->reflected += c->reflected;
    s->transmitted += c->transmitted;
    s->absorbed += c->absorbed;
    s->escaped += c->escaped;
    s->back_face_hits += c->back_face_hits;
    s->terminated += c->terminated + c->capped;
    s->bounce_capped += c->capped;
    s->fired_power_w_per_hz += c->fired_power;
    s->absorbed_power_w_per_hz += c->absorbed_power;
    s->escaped_power_w_per_hz += c->escaped_power;
    s->atmosphere_power_w_per_hz += c->atmosphere_power;
    s->terminated_power_w_per_hz += c->terminated_power;
    s->mean_bounces = s->fired ? (double)s->hits / (double)s->fired : 0.0;
    s->rays += c->rays;
}

void photon_stats_merge(photon_stats *sum, const photon_stats *p, uint32_t passes)
{
    if (passes == 1) {
        *sum = *p;
        return;
    }
    double w = 1.0 / passes, keep = 1.0 - w;
    sum->fired += p->fired;
    sum->hits += p->hits;
    sum->reflected += p->reflected;
    sum->transmitted += p->transmitted;
    sum->absorbed += p->absorbed;
    sum->escaped += p->escaped;
    sum->back_face_hits += p->back_face_hits;
    sum->terminated += p->terminated;
    sum->bounce_capped += p->bounce_capped;
    sum->rays += p->rays;
    sum->absorbed_power_w_per_hz =
        keep * sum->absorbed_power_w_per_hz + w * p->absorbed_power_w_per_hz;
    sum->escaped_power_w_per_hz =
        keep * sum->escaped_power_w_per_hz + w * p->escaped_power_w_per_hz;
    sum->atmosphere_power_w_per_hz =
        keep * sum->atmosphere_power_w_per_hz + w * p->atmosphere_power_w_per_hz;
    sum->fired_power_w_per_hz = keep * sum->fired_power_w_per_hz + w * p->fired_power_w_per_hz;
    sum->terminated_power_w_per_hz =
        keep * sum->terminated_power_w_per_hz + w * p->terminated_power_w_per_hz;
    sum->mean_bounces = sum->fired ? (double)sum->hits / (double)sum->fired : 0.0;
    sum->seconds += p->seconds;
    sum->seconds_emission_table += p->seconds_emission_table;
    sum->seconds_tracing += p->seconds_tracing;
    sum->seconds_index += p->seconds_index;
}
