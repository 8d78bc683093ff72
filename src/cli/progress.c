/* Progress display and interrupt handling for the long-running commands. */
#include "progress.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"

/* The one piece of process-wide state in thzmap: a signal handler can reach nothing
 * else. Written only by the handler, read by the progress callback. */
static volatile sig_atomic_t cli_interrupted = 0;

static void cli_on_signal(int sig)
{
    cli_interrupted = sig;
    thz_mpi_interrupt(); /* rank 0 waiting for another rank stops waiting (async-signal-safe) */
}

int cli_interrupt_signal(void)
{
    return (int)cli_interrupted;
}

void cli_signals_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = cli_on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND;   /* a second Ctrl-C ends the process at once */
    sigaction(SIGINT, &sa, NULL); /* also where a script's shell ignored it for a
                                     background job: `kill -INT` still stops the run */
    sigaction(SIGTERM, &sa, NULL);
    /* a closed terminal or ssh session stops the run as Ctrl-C does (it was killed
     * mid-commit, leaving its lock and staging directory beside OUTDIR); but a SIGHUP
     * ignored when thzmap starts stays ignored: `nohup` asks for that (closing the
     * terminal ended a nohup run) */
    struct sigaction hup;
    if (sigaction(SIGHUP, NULL, &hup) != 0 || hup.sa_handler != SIG_IGN)
        sigaction(SIGHUP, &sa, NULL);
    /* progress piped to a reader that left (`2>&1 | head -1`): the writes fail, the run
     * goes on (SIGPIPE killed it mid-commit too) */
    signal(SIGPIPE, SIG_IGN);
}

void cli_signals_hold(sigset_t *before)
{
    sigset_t stop;
    sigemptyset(&stop);
    sigaddset(&stop, SIGINT);
    sigaddset(&stop, SIGTERM);
    sigaddset(&stop, SIGHUP);
    sigaddset(&stop, SIGPIPE);
    sigprocmask(SIG_BLOCK, &stop, before);
}

void cli_signals_release(const sigset_t *before)
{
    sigprocmask(SIG_SETMASK, before, NULL);
}

int cli_end_by_signal(int rc)
{
    int sig = cli_interrupt_signal();
    if (sig == 0 || rc != 128 + sig)
        return rc;
    /* as the signal's default action would have ended it, after cleaning up: the shell
     * that started thzmap sees it ended by the signal (a script's loop stops on Ctrl-C) */
    fflush(NULL);
    signal(sig, SIG_DFL);
    raise(sig);
    return rc; /* the signal blocked: the status says it */
}

void cli_progress_init(cli_progress *p, const char *command, bool quiet)
{
    memset(p, 0, sizeof *p);
    p->out = stderr;
    p->command = command;
    p->quiet = quiet;
    /* a line redrawn in place needs a terminal that moves the cursor: not TERM=dumb (an
     * Emacs buffer, some CI consoles showed ^M^[[K), nor one with no TERM at all */
    const char *term = getenv("TERM");
    p->tty = isatty(fileno(stderr)) != 0 && term && *term && strcmp(term, "dumb") != 0;
    p->last_report_s = cli_now_s();
}

void cli_progress_sensors(cli_progress *p, const thz_scene *scene, long only)
{
    p->scene = scene;
    p->n_sensors = only >= 0 ? 1 : thz_scene_sensor_count(scene);
}

/* ", sensor 'NAME' (k/S)" for a render report of a run of several sensors, else "". */
static void cli_progress_sensor_text(const cli_progress *p, const thz_progress *pr, char *out,
                                     size_t size)
{
    out[0] = '\0';
    if (!p->scene || p->n_sensors < 2 || strcmp(pr->stage, "render") != 0)
        return;
    size_t k = p->restarts % p->n_sensors;
    thz_sensor_info info;
    if (thz_scene_sensor(p->scene, k, &info) == THZ_OK)
        snprintf(out, size, ", sensor '%s' (%zu/%zu)", info.name, k + 1, p->n_sensors);
}

/* The share of the channel's render done: the sensors before this one in the pass, and
 * this one's rows. */
static double cli_render_share(const cli_progress *p, double rows_frac)
{
    if (!p->scene || p->n_sensors < 2)
        return rows_frac;
    return ((double)(p->restarts % p->n_sensors) + rows_frac) / (double)p->n_sensors;
}

/* The unit a stage counts in. */
static const char *cli_stage_unit(const char *stage)
{
    if (strcmp(stage, "photons") == 0)
        return "photons";
    if (strcmp(stage, "render") == 0)
        return "rows";
    if (strcmp(stage, "prepare") == 0)
        return "objects";
    if (strcmp(stage, "bands") == 0)
        return "candidate channels";
    return "steps";
}

/* Prints ", run ETA 12 s" for the whole run: from the share of the channels done so far
 * (photons the first half of a channel when it fires any), else the estimate less the
 * time spent; nothing without a plan or time left. frac: the stage's share done. */
static void cli_progress_eta(const cli_progress *p, const thz_progress *pr, double frac, double now)
{
    double run_elapsed = now - p->run_start_s;
    double render = cli_render_share(p, frac);
    double share = (double)pr->channel + (strcmp(pr->stage, "photons") == 0 ? 0.5 * frac
                                          : p->photons_seen                 ? 0.5 + 0.5 * render
                                                                            : render);
    share /= (double)(pr->n_channels ? pr->n_channels : 1);
    double eta = share > 0.02 ? run_elapsed * (1.0 - share) / share : p->estimate_s - run_elapsed;
    if (eta > 0.0 && p->run_start_s > 0.0) {
        char left[32];
        cli_format_seconds_left(left, sizeof left, eta);
        fprintf(p->out, ", run ETA %s", left);
    }
}

static void cli_progress_draw_tty(cli_progress *p, const thz_progress *pr, double now)
{
    double elapsed = now - p->stage_start_s;
    double frac = pr->total ? (double)pr->done / (double)pr->total : 0.0;
    double rate = elapsed > 0.0 ? (double)pr->done / elapsed : 0.0;
    if (strcmp(pr->stage, "output") == 0) {
        fprintf(p->out, "\r\033[Kthzmap %s: writing the results", p->command);
        fflush(p->out);
        p->line_open = true;
        return;
    }
    if (strcmp(pr->stage, "bands") == 0) { /* thz_bands_select: its renders, one by one */
        char of[32] = " (nominal)";        /* the count of renders, once known */
        if (pr->n_channels)
            snprintf(of, sizeof of, "/%zu", pr->n_channels);
        fprintf(p->out, "\r\033[Kthzmap %s: render %zu%s, %llu/%llu candidate channels (%.0f %%)",
                p->command, pr->channel + 1, of, (unsigned long long)pr->done,
                (unsigned long long)pr->total, 100.0 * frac);
        if (rate > 0.0)
            fprintf(p->out, ", %.3g channels/s", rate);
        fflush(p->out);
        p->line_open = true;
        return;
    }
    if (strcmp(pr->stage, "prepare") == 0) { /* before the channels: the run's, not one's */
        fprintf(p->out,
                "\r\033[Kthzmap %s: preparing the back-side sources: %llu/%llu objects (%.0f %%), "
                "%.1f s",
                p->command, (unsigned long long)pr->done, (unsigned long long)pr->total,
                100.0 * frac, elapsed);
        fflush(p->out);
        p->line_open = true;
        return;
    }
    const char *unit = cli_stage_unit(pr->stage);
    bool named = strcmp(unit, pr->stage) == 0; /* "photons 500/1000", not "... photons" */
    char sensor[160];
    cli_progress_sensor_text(p, pr, sensor, sizeof sensor);
    fprintf(p->out, "\r\033[Kthzmap %s: channel %zu/%zu, %s %llu/%llu%s%s (%.0f %%)%s", p->command,
            pr->channel + 1, pr->n_channels, pr->stage, (unsigned long long)pr->done,
            (unsigned long long)pr->total, named ? "" : " ", named ? "" : unit, 100.0 * frac,
            sensor);
    if (rate > 0.0)
        fprintf(p->out, ", %.3g %s/s", rate, unit);
    cli_progress_eta(p, pr, frac, now);
    fflush(p->out);
    p->line_open = true;
}

static void cli_progress_line(cli_progress *p, const thz_progress *pr, double now)
{
    double elapsed = now - p->stage_start_s;
    const char *unit = cli_stage_unit(pr->stage);
    if (strcmp(pr->stage, "prepare") == 0) {
        fprintf(p->out, "thzmap %s: back-side sources: %llu objects in %.2f s\n", p->command,
                (unsigned long long)pr->done, elapsed);
        fflush(p->out);
        return;
    }
    if (strcmp(pr->stage, "bands") == 0) {
        char of[32] = " (nominal)";
        if (pr->n_channels)
            snprintf(of, sizeof of, "/%zu", pr->n_channels);
        fprintf(p->out, "thzmap %s: render %zu%s: %llu candidate channels in %.2f s\n", p->command,
                pr->channel + 1, of, (unsigned long long)pr->done, elapsed);
        fflush(p->out);
        return;
    }
    fprintf(p->out, "thzmap %s: channel %zu/%zu, %s: %llu %s in %.2f s", p->command,
            pr->channel + 1, pr->n_channels, pr->stage, (unsigned long long)pr->done, unit,
            elapsed);
    if (elapsed > 0.0 && strcmp(pr->stage, "output") != 0)
        fprintf(p->out, " (%.3g %s/s)", (double)pr->done / elapsed, unit);
    char sensor[160];
    cli_progress_sensor_text(p, pr, sensor, sizeof sensor);
    fputs(sensor, p->out);
    fputc('\n', p->out);
    fflush(p->out);
}

/* Not a terminal (a log file, a batch system's output): a line within a long stage,
 * "thzmap simulate: channel 1/6, photons: 40 % (400000000 of 1000000000 photons), 612 s,
 * run ETA 7650 s", each time it passes another tenth at least CLI_LINE_EVERY_S after the
 * stage's start or its last such line; before, a stage of an hour said nothing until
 * it ended. */
#define CLI_LINE_EVERY_S 10.0

static void cli_progress_partial_line(cli_progress *p, const thz_progress *pr, double now)
{
    double frac = (double)pr->done / (double)pr->total;
    int tenth = (int)(10.0 * frac);
    if (tenth <= p->line_tenth || now - p->last_line_s < CLI_LINE_EVERY_S ||
        (strcmp(pr->stage, "photons") != 0 && strcmp(pr->stage, "render") != 0))
        return;
    p->line_tenth = tenth;
    p->last_line_s = now;
    char sensor[160];
    cli_progress_sensor_text(p, pr, sensor, sizeof sensor);
    fprintf(p->out, "thzmap %s: channel %zu/%zu, %s: %.0f %% (%llu of %llu %s), %.0f s%s",
            p->command, pr->channel + 1, pr->n_channels, pr->stage, 100.0 * frac,
            (unsigned long long)pr->done, (unsigned long long)pr->total, cli_stage_unit(pr->stage),
            now - p->stage_start_s, sensor);
    cli_progress_eta(p, pr, frac, now);
    fputc('\n', p->out);
    fflush(p->out);
}

int cli_progress_report(void *user, const thz_progress *pr)
{
    cli_progress *p = user;
    if (cli_interrupted)
        return 1;
    if (p->quiet)
        return 0;
    double now = cli_now_s();
    double previous = p->last_report_s;
    p->last_report_s = now;
    bool other_stage = !p->stage || strcmp(p->stage, pr->stage) != 0 || p->channel != pr->channel;
    if (other_stage)
        p->restarts = 0;
    else if (pr->done < p->last_done) /* the next sensor, or the next pass */
        p->restarts++;
    if (other_stage || pr->done < p->last_done) {
        p->stage = pr->stage;
        p->channel = pr->channel;
        p->completed = false;
        /* A channel's stage reports done = 0 when it starts (thz_progress): its clock
         * starts now, not at the report before, which may be the set-up before the run
         * or the previous stage. A pass that starts over counts from the end of the
         * previous pass (the time between belongs to the channel's rendering). */
        p->stage_start_s = other_stage && pr->done == 0 ? now : previous;
        p->last_draw_s = 0.0;
        p->last_line_s = p->stage_start_s;
        p->line_tenth = 0;
    }
    p->last_done = pr->done;
    if (strcmp(pr->stage, "photons") == 0)
        p->photons_seen = true;
    bool done = pr->total > 0 && pr->done >= pr->total;
    if (p->tty) {
        if (done || now - p->last_draw_s >= 0.1) {
            cli_progress_draw_tty(p, pr, now);
            p->last_draw_s = now;
        }
    } else if (done && !p->completed && strcmp(pr->stage, "output") != 0) {
        cli_progress_line(p, pr, now);
    } else if (!done && pr->total > 0) {
        cli_progress_partial_line(p, pr, now);
    }
    if (done)
        p->completed = true;
    return 0;
}

void cli_progress_finish(cli_progress *p)
{
    if (p->line_open) {
        fputs("\r\033[K", p->out);
        fflush(p->out);
        p->line_open = false;
    }
}

void cli_progress_warning(void *user, const char *message)
{
    cli_progress *p = user;
    cli_progress_finish(p); /* a warning gets its own line, even with --quiet */
    fprintf(p->out, "thzmap %s: warning: %s\n", p->command, message);
    fflush(p->out);
}

void cli_progress_plan(void *user, const thz_run_plan *plan)
{
    cli_progress *p = user;
    double total = plan->seconds_photons + plan->seconds_render;
    p->estimate_s = total;
    p->run_start_s = cli_now_s();
    if (p->quiet)
        return;
    char target[256] = "";
    const char *source = plan->target_source ? plan->target_source : "given";
    if (plan->target_noise_k > 0.0 && plan->memory_stop)
        snprintf(target, sizeof target,
                 ", about %u photon passes per channel, where they stop at the memory they may "
                 "hold (half of what the process may have), short of the noise target of %g K "
                 "(%s; --photons N fires N photons once)",
                 plan->passes, plan->target_noise_k, source);
    else if (plan->target_noise_k > 0.0)
        snprintf(target, sizeof target,
                 ", up to about %u pass%s per channel to reach the noise target of %g K (%s)",
                 plan->passes, plan->passes == 1 ? "" : "es", plan->target_noise_k, source);
    char memory[32], available[40] = "";
    cli_format_bytes(memory, sizeof memory, plan->memory_bytes);
    if (plan->available_bytes > 0) { /* 0: unknown */
        strcpy(available, " of ");
        cli_format_bytes(available + 4, sizeof available - 4, plan->available_bytes);
    }
    fprintf(
        p->out, "thzmap %s: estimate: %.3g s (photons %.3g s, rendering %.3g s)%s; memory %s%s\n",
        p->command, total, plan->seconds_photons, plan->seconds_render, target, memory, available);
    fflush(p->out);
}

void cli_format_seconds_left(char *buf, size_t size, double seconds)
{
    if (seconds < 1.0) /* "0 s" would say the work is done */
        snprintf(buf, size, "< 1 s");
    else
        snprintf(buf, size, "%.0f s", seconds);
}

void cli_format_bytes(char *buf, size_t size, uint64_t bytes)
{
    double gib = (double)bytes / 1073741824.0;
    if (gib >= 1.0)
        snprintf(buf, size, "%.3g GiB", gib);
    else
        snprintf(buf, size, "%.3g MiB", (double)bytes / 1048576.0);
}

void cli_count_line_start(cli_count_line *c, bool tty)
{
    *c = (cli_count_line){.tty = tty, .start_s = cli_now_s()};
}

bool cli_count_line_show(cli_count_line *c, const char *command, const char *what, uint64_t done,
                         uint64_t total)
{
    double now = cli_now_s();
    if (!total || now - c->start_s < 1.0)
        return false;
    double frac = (double)done / (double)total;
    int tenth = (int)(10.0 * frac);
    if (c->tty ? now - c->last_draw_s < 0.1 : tenth <= c->tenth)
        return false;
    c->last_draw_s = now;
    c->tenth = tenth;
    /* the percentage rounded down, as the tenths are: 19.8 % is not a second "20 %" */
    fprintf(stderr, "%sthzmap %s: checking %s: %d %% (%llu of %llu frames), %.1f s%s",
            c->tty ? "\r\033[K" : "", command, what, (int)(100.0 * frac), (unsigned long long)done,
            (unsigned long long)total, now - c->start_s, c->tty ? "" : "\n");
    fflush(stderr);
    return true;
}
