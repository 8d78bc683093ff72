/* Progress display on stderr for long runs, and Ctrl-C handling.
 *
 * When stderr is a terminal: one line, updated in place (channel i/n, stage, units done,
 * rate, ETA in s). Otherwise: one line per channel and stage when it completes, and
 * within a stage that runs long a line per tenth, at least 10 s apart. No
 * progress with --quiet; warnings always. The progress callback also carries cancellation: once
 * SIGINT or SIGTERM arrived it returns non-zero, so the run stops and removes its staging
 * directory.
 */
#ifndef THZ_CLI_PROGRESS_H
#define THZ_CLI_PROGRESS_H

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "thzmap/thzmap.h"

typedef struct cli_progress {
    FILE *out;           /* stderr */
    const char *command; /* "simulate", "render" */
    bool quiet;
    bool tty;
    bool line_open;    /* a terminal line is being updated */
    const char *stage; /* current (stage, channel), NULL before the first report */
    size_t channel;
    uint64_t last_done;
    bool completed;       /* the completion of the current stage was shown */
    double stage_start_s; /* a channel's stage: its first report (done = 0, when it
                             starts); a pass that starts over: the report before */
    double last_report_s;
    double last_draw_s;
    double last_line_s; /* not a terminal: the stage's start or its last partial line */
    int line_tenth;     /* not a terminal: the tenth of the stage that line showed */
    double run_start_s; /* when the plan was told (0: no plan) */
    double estimate_s;  /* the plan's estimate of the whole run, s */
    bool photons_seen;  /* the run fires photons (half of each channel's share) */
    /* The sensors a run renders, one after the other in each pass (cli_progress_sensors;
     * none: not told): each starts its rows from 0, which the lines name and the run's
     * ETA counts (10 sensors made it swing between 10 s and 1 s). */
    const thz_scene *scene;
    size_t n_sensors;
    size_t restarts; /* of the channel's render rows: pass * n_sensors + sensor */
} cli_progress;

/* Tells p the sensors the run renders: all of the scene's, or `only` (>= 0). */
void cli_progress_sensors(cli_progress *p, const thz_scene *scene, long only);

void cli_progress_init(cli_progress *p, const char *command, bool quiet);

/* The thz_progress_fn: draws, and returns non-zero once an interrupt arrived. */
int cli_progress_report(void *user, const thz_progress *progress);

/* The run's warning callback: prints "thzmap CMD: warning: MESSAGE" on its own line of
 * stderr (with --quiet too). */
void cli_progress_warning(void *user, const char *message);

/* The run's plan callback: prints the estimate of time and memory before the run
 * (not with --quiet) and keeps it for the whole-run ETA. */
void cli_progress_plan(void *user, const thz_run_plan *plan);

/* A count of items checked (a sequence's frames), shown once it has taken 1 s: on a
 * line redrawn at most every 0.1 s on a terminal, else a line each time it passes
 * another tenth. `thzmap batch` and `thzmap validate` show their checks of a sequence so. */
typedef struct cli_count_line {
    bool tty;           /* stderr is a terminal */
    double start_s;     /* when the count began */
    double last_draw_s; /* the last line's time */
    int tenth;          /* not a terminal: the last tenth printed */
} cli_count_line;

void cli_count_line_start(cli_count_line *c, bool tty);

/* Prints "thzmap COMMAND: checking WHAT: 40 % (400 of 1000 frames), 2.1 s" on stderr when
 * due; true when it did (on a terminal the line is then left open, without its newline). */
bool cli_count_line_show(cli_count_line *c, const char *command, const char *what, uint64_t done,
                         uint64_t total);

/* Ends the terminal line, if one is open. */
void cli_progress_finish(cli_progress *p);

/* A time still to go, "12 s", for an ETA: "< 1 s" below 1 s (never "0 s" while work
 * remains). */
void cli_format_seconds_left(char *buf, size_t size, double seconds);

/* A size in memory, "1.5 GiB", or in MiB below 1 GiB ("0.625 MiB", not "0.00061 GiB"). */
void cli_format_bytes(char *buf, size_t size, uint64_t bytes);

/* Installs the SIGINT/SIGTERM handler (one-shot: a second signal kills at once). */
void cli_signals_install(void);

/* Holds SIGINT, SIGTERM, SIGHUP and SIGPIPE (into *before, the mask to restore) over a
 * piece of work that must end whole or not at all, such as a commit; they are delivered
 * when cli_signals_release restores the mask. */
void cli_signals_hold(sigset_t *before);
void cli_signals_release(const sigset_t *before);

/* The signal that interrupted the run (SIGINT, SIGTERM), 0 if none: the exit status is
 * 128 + it, the shell's convention (130 for Ctrl-C, 143 for SIGTERM). */
int cli_interrupt_signal(void);
/* The end of a command that returned rc: when rc is 128 + the signal that interrupted it
 * (SIGINT, SIGTERM, SIGHUP; its outputs cleaned up), the process ends by that signal
 * (its default action), so that its parent sees it killed by the signal; otherwise, or
 * if it returns, rc. */
int cli_end_by_signal(int rc);

#endif
