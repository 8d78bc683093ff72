/* Wall-clock time for timings (summary.json, progress, --max-seconds). */
#ifndef THZ_CORE_CLOCK_H
#define THZ_CORE_CLOCK_H

/* Seconds on a monotonic clock (differences only: the origin is arbitrary). */
double thz_now_s(void);

#endif
