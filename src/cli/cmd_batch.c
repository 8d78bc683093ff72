/* thzmap batch SEQUENCE.json -o OUTDIR: run a sequence of frames (keyframes, sweeps, a
 * list of scenes) through the library's thz_batch_run, with progress over the whole
 * batch on stderr (a line per frame, and within frames a redrawn line on a terminal or
 * a line per tenth of the batch otherwise) and Ctrl-C/SIGTERM ending it cleanly
 * (finished frames stay; running it again resumes). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "cli_mpi.h"
#include "frame_warnings.h"
#include "progress.h"
#include "run_command.h"
#include "thzmap/thzmap.h"

static void batch_usage(FILE *f)
{
    fprintf(f, "usage: thzmap batch SEQUENCE.json -o OUTDIR [options]\n\n"
               "Runs every frame of a sequence file (thzmap-sequence/1: keyframes interpolated\n"
               "in time, or a list of scene files; sweeps) as 'thzmap simulate' would, each\n"
               "into OUTDIR/frame-NNNNN/\n"
               "(OUTDIR/sweep-NN/frame-NNNNN/ with a sweep); writes OUTDIR/batch.json and per\n"
               "sensor and channel a movie S.band-NN.mp4 of the brightness temperature.\n"
               "Frames that differ from the previous one only in their sensors are rendered\n"
               "from the photons of the first such frame, as 'thzmap render' would: photons\n"
               "are fired once for a moving camera.\n"
               "Run again with the same command, it skips every finished frame whose inputs\n"
               "did not change (resuming a killed or interrupted batch).\n\n"
               "options:\n"
               "  -o, --output OUTDIR   where the results go (required)\n"
               "  --threads T           threads to use (default: all cores)\n"
               "  --no-movies           the frames and batch.json only, no movies\n"
               "  -q, --quiet           no progress output (warnings are still printed)\n"
               "  -h, --help            this help\n");
}

typedef struct batch_cli {
    bool quiet;
    bool no_movies;     /* --no-movies */
    bool tty;           /* stderr is a terminal: the progress within frames is redrawn */
    bool line_open;     /* a redrawn line is on the terminal */
    double last_draw_s; /* when it was drawn, s */
    int last_tenth;     /* not a terminal: the last tenth of the batch printed */
    size_t frame;       /* the frame running (its warnings name it), when in_frame */
    bool in_frame;
    bool checking; /* the frames' memory check has begun */
    /* when the first frame began (its s since the batch's start): the ETAs count from
     * there, not from the sequence's load and memory check (a 5000-frame batch's 8.6 s of
     * checks made its ETA after one frame 43779 s, for about 1 100 s of frames) */
    bool frames_began;
    double frames_t0_s;
    /* the sequence's load, then the memory check (its own count, so that the batch's
     * tenths do not start where a long check ended) */
    cli_count_line check;
    bool movies_said;            /* "encoding the movies" printed (the stage comes twice) */
    const thz_sequence *seq;     /* the frames' directories, which the warnings name */
    cli_frame_warnings warnings; /* printed once, the later frames' same counted */
} batch_cli;

/* Within a frame: the share of the whole batch done and its ETA, on a line redrawn at
 * most every 0.1 s on a terminal, else a line each time it passes another tenth. */
static void batch_show_run(batch_cli *b, const thz_batch_progress *p)
{
    double start = p->n_frames ? (double)p->reused / (double)p->n_frames : 0.0;
    char eta[64] = "", left[32];
    if (p->fraction - start > 0.01) {
        cli_format_seconds_left(left, sizeof left,
                                (p->seconds - b->frames_t0_s) * (1.0 - p->fraction) /
                                    (p->fraction - start));
        snprintf(eta, sizeof eta, ", ETA %s", left);
    }
    if (b->tty) {
        double now = cli_now_s();
        if (now - b->last_draw_s < 0.1)
            return;
        b->last_draw_s = now;
        fprintf(stderr, "\r\033[Kthzmap batch: frame %zu/%zu, %.0f %% of the batch, %.1f s%s",
                p->frame + 1, p->n_frames, 100.0 * p->fraction, p->seconds, eta);
        b->line_open = true;
    } else {
        int tenth = (int)(10.0 * p->fraction);
        if (tenth <= b->last_tenth || tenth >= 10)
            return;
        b->last_tenth = tenth;
        fprintf(stderr, "thzmap batch: %d %% of the batch done (in frame %zu/%zu), %.1f s%s\n",
                10 * tenth, p->frame + 1, p->n_frames, p->seconds, eta);
    }
    fflush(stderr);
}

static int batch_on_load_progress(void *user, const thz_progress *p);

static int batch_on_progress(void *user, const thz_batch_progress *p)
{
    batch_cli *b = user;
    if (cli_interrupt_signal())
        return 1;
    b->in_frame = !strcmp(p->stage, "frame") || !strcmp(p->stage, "run");
    b->frame = p->frame;
    if (b->in_frame && !b->frames_began) {
        b->frames_began = true;
        b->frames_t0_s = p->seconds;
    }
    if (b->quiet)
        return 0;
    if (!strcmp(p->stage, "run")) {
        batch_show_run(b, p);
        return 0;
    }
    if (!strcmp(p->stage, "check")) { /* the frames' memory, before the first runs */
        if (!b->checking) {
            b->checking = true;
            cli_count_line_start(&b->check, b->tty);
        }
        thz_progress lp = {.stage = "check", .done = p->frame, .total = p->n_frames};
        batch_on_load_progress(b, &lp);
        return 0;
    }
    if (b->line_open) {
        fputs("\r\033[K", stderr);
        b->line_open = false;
    }
    size_t finished = p->computed + p->reused;
    if (!strcmp(p->stage, "frame")) {
        char eta[64] = "", left[32];
        if (p->computed > 0 && finished < p->n_frames) { /* no ETA once every frame is done */
            double per_frame = (p->seconds - b->frames_t0_s) / (double)p->computed;
            cli_format_seconds_left(left, sizeof left,
                                    per_frame * (double)(p->n_frames - finished));
            snprintf(eta, sizeof eta, ", ETA %s", left);
        }
        /* finished counts the frames found done in OUTDIR ahead of this one too */
        fprintf(stderr,
                "thzmap batch: frame %zu/%zu (%zu of %zu frames finished so far: %zu computed, "
                "%zu already done), %.1f s%s\n",
                p->frame + 1, p->n_frames, finished, p->n_frames, p->computed, p->reused,
                p->seconds, eta);
    } else if (!strcmp(p->stage, "movie") && !b->movies_said) { /* reported again after */
        b->movies_said = true;
        fprintf(stderr, "thzmap batch: %zu frame%s done (%.1f s); encoding the movies\n",
                p->n_frames, p->n_frames == 1 ? "" : "s", p->seconds);
    }
    return 0;
}

/* While the sequence loads (thz_sequence_load_ctx checks every frame's scene, a few ms
 * each) and while its frames' memory is checked: the share of frames checked. */
static int batch_on_load_progress(void *user, const thz_progress *p)
{
    batch_cli *b = user;
    if (!b->quiet && cli_count_line_show(&b->check, "batch",
                                         !strcmp(p->stage, "check") ? "the frames' memory"
                                                                    : "the frames' scenes",
                                         p->done, p->total))
        b->line_open = b->tty;
    return 0;
}

/* Loads the sequence, showing the check of its frames when it takes long. */
static thz_status batch_load(batch_cli *b, const char *path, thz_sequence **seq, thz_error *err)
{
    thz_context *ctx = thz_context_create();
    if (!ctx) {
        err->status = THZ_ERR_NOMEM;
        snprintf(err->message, sizeof err->message, "out of memory");
        return err->status;
    }
    cli_count_line_start(&b->check, b->tty);
    thz_context_set_progress(ctx, batch_on_load_progress, b);
    thz_status st = thz_sequence_load_ctx(ctx, path, NULL, seq, err);
    thz_context_destroy(ctx);
    if (b->line_open) {
        fputs("\r\033[K", stderr);
        b->line_open = false;
    }
    return st;
}

/* A frame's run: no per-stage display (the batch shows frames), but Ctrl-C cancels. */
static int batch_on_run_progress(void *user, const thz_progress *p)
{
    (void)user;
    (void)p;
    return cli_interrupt_signal() != 0;
}

/* A frame's warning names the frame (a sequence's frames often warn alike). */
static void batch_on_warning(void *user, const char *message)
{
    batch_cli *b = user;
    if (!cli_frame_warnings_first(&b->warnings, b->in_frame ? b->frame : CLI_NO_FRAME, message))
        return;
    if (b->line_open) {
        fputs("\r\033[K", stderr);
        b->line_open = false;
    }
    thz_frame_info fi;
    if (b->in_frame)
        fprintf(stderr, "thzmap batch: warning: %s: %s\n",
                thz_sequence_frame(b->seq, b->frame, &fi) == THZ_OK ? fi.dir : "?", message);
    else
        fprintf(stderr, "thzmap batch: warning: %s\n", message);
}

/* A rank other than 0 of an MPI batch: serves every frame rank 0 runs. A failure ends
 * the job, since rank 0 waits for it. */
static int batch_member(const thz_sequence *seq, int threads)
{
    thz_error err = {0};
    thz_context *ctx = thz_context_create();
    if (!ctx) {
        fprintf(stderr, "thzmap batch (MPI rank %d): out of memory\n", cli_mpi_rank());
        cli_mpi_abort(CLI_EXIT_FAILURE);
    }
    thz_context_set_threads(ctx, threads);
    if (thz_mpi_serve_batch(ctx, seq, &err) != THZ_OK) {
        fprintf(stderr, "thzmap batch (MPI rank %d): %s\n", cli_mpi_rank(), err.message);
        cli_mpi_abort(err.status == THZ_ERR_INPUT ? CLI_EXIT_USAGE : CLI_EXIT_FAILURE);
    }
    thz_context_destroy(ctx);
    return CLI_EXIT_OK;
}

/* Parses argv; -1 to go on, or the exit status. */
static int batch_parse(int argc, char **argv, const char **seq_path, const char **outdir,
                       uint64_t *threads, batch_cli *b)
{
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (cli_is_help(arg)) {
            batch_usage(stdout);
            return CLI_EXIT_OK;
        }
        if (!strcmp(arg, "-o") || !strcmp(arg, "--output") || !strcmp(arg, "--threads")) {
            if (cli_refuse_repeat("batch", argv, i) != -1)
                return CLI_EXIT_USAGE;
            if (i + 1 >= argc)
                return cli_usage_error("batch", "%s needs a value", arg);
            if (cli_looks_like_option(argv[i + 1]))
                return cli_usage_error("batch", "%s needs a value, got the option '%s'", arg,
                                       argv[i + 1]);
            const char *val = argv[++i];
            if (!strcmp(arg, "--threads")) {
                if (!cli_parse_u64("batch", arg, val, 1, THZ_MAX_THREADS, threads))
                    return CLI_EXIT_USAGE;
            } else {
                *outdir = val;
            }
        } else if (!strcmp(arg, "--quiet") || !strcmp(arg, "-q")) {
            b->quiet = true;
        } else if (!strcmp(arg, "--no-movies")) {
            b->no_movies = true;
        } else if (arg[0] == '-' && arg[1]) {
            return cli_usage_error("batch", "unknown option '%s'", arg);
        } else if (!*seq_path) {
            *seq_path = arg;
        } else {
            return cli_usage_error("batch", "unexpected argument '%s'", arg);
        }
    }
    if (!*seq_path)
        return cli_usage_error("batch", "no sequence file given");
    if (!*outdir)
        return cli_usage_error("batch", "no output directory given (-o OUTDIR)");
    /* before every frame's scene is built and checked (seconds for a few dozen frames in
     * humid air), not after */
    return cli_refuse_file_outdir("batch", *outdir);
}

int cmd_batch(int argc, char **argv)
{
    const char *seq_path = NULL, *outdir = NULL;
    uint64_t threads = 0;
    batch_cli b = {.tty = isatty(STDERR_FILENO) != 0};
    thz_sequence *seq = NULL;
    /* Under mpirun every rank parses and loads alike; rank 0 alone says what is wrong. */
    cli_mpi_quiet_begin();
    int rc = batch_parse(argc, argv, &seq_path, &outdir, &threads, &b);
    if (rc < 0)
        threads = cli_threads_check("batch", threads);
    thz_error err = {0};
    if (rc < 0 && batch_load(&b, seq_path, &seq, &err) != THZ_OK)
        rc = cli_fail(&err);
    cli_mpi_quiet_end();
    int lead_rc = rc, failed = cli_mpi_agree(rc < 0, rc, &lead_rc);
    if (failed >= 0) {
        thz_sequence_destroy(seq);
        if (lead_rc >= 0)
            return lead_rc;
        if (cli_mpi_rank() == 0)
            fprintf(stderr,
                    "thzmap batch: MPI rank %d could not load the sequence rank 0 did (is %s "
                    "the same file on every node?)\n",
                    failed, seq_path);
        return CLI_EXIT_FAILURE;
    }
    b.seq = seq;
    bool shared = cli_mpi_size() > 1;
    if (shared && cli_mpi_rank() > 0) {
        rc = batch_member(seq, (int)threads);
        thz_sequence_destroy(seq);
        return rc;
    }

    cli_signals_install();
    thz_context *ctx = thz_context_create();
    if (!ctx) {
        thz_sequence_destroy(seq);
        fprintf(stderr, "thzmap batch: out of memory\n");
        if (shared) /* the other ranks wait for this one: end them too */
            cli_mpi_abort(CLI_EXIT_FAILURE);
        return CLI_EXIT_FAILURE;
    }
    thz_context_set_threads(ctx, (int)threads);
    if (shared && thz_context_set_mpi(ctx, &err) != THZ_OK)
        cli_mpi_abort(cli_fail(&err));
    thz_context_set_progress(ctx, batch_on_run_progress, &b);
    thz_context_set_warning(ctx, batch_on_warning, &b);
    if (!b.quiet)
        fprintf(stderr, "thzmap batch: %zu frame%s (%zu sweep value%s x %zu frame%s) into %s\n",
                thz_sequence_frame_count(seq), thz_sequence_frame_count(seq) == 1 ? "" : "s",
                thz_sequence_sweep_count(seq), thz_sequence_sweep_count(seq) == 1 ? "" : "s",
                thz_sequence_frames_per_sweep(seq),
                thz_sequence_frames_per_sweep(seq) == 1 ? "" : "s", outdir);
    thz_batch_options opt = {.progress = batch_on_progress,
                             .progress_user = &b,
                             .open_output = cli_exit_guard(),
                             .no_movies = b.no_movies};
    thz_batch_result res;
    thz_status st = thz_batch_run(ctx, seq, outdir, &opt, &res, &err);
    if (b.line_open)
        fputs("\r\033[K", stderr);
    rc = CLI_EXIT_OK;
    /* a failure under an interrupt is the interrupt's (a child ended by the same Ctrl-C) */
    if (st == THZ_ERR_CANCELLED || (st != THZ_OK && cli_interrupt_signal())) {
        fprintf(stderr,
                "thzmap batch: interrupted%s after %zu new frame%s; finished frames stay in %s "
                "(run the same command again to resume)\n",
                cli_mpi_signal_note(cli_interrupt_signal()), res.computed,
                res.computed == 1 ? "" : "s", outdir);
        rc = cli_interrupt_signal() ? 128 + cli_interrupt_signal() : CLI_EXIT_INTERRUPTED;
    } else if (st != THZ_OK) {
        rc = cli_fail(&err);
    } else if (!b.quiet) {
        printf("thzmap batch: %zu frame%s (%zu computed, %zu already done), %zu movie%s",
               res.n_frames, res.n_frames == 1 ? "" : "s", res.computed, res.reused, res.movies,
               res.movies == 1 ? "" : "s");
        if (shared)
            printf(", %d MPI ranks (%.3g MB communicated)", cli_mpi_size(),
                   1e-6 * (double)thz_context_mpi_bytes(ctx));
        printf(", %.2f s; results in %s\n", res.seconds, outdir);
    }
    cli_frame_warnings_finish(&b.warnings, "batch", "each frame's summary.json has its own", true);
    if (shared && rc != CLI_EXIT_OK) /* the other ranks may be waiting for rank 0 */
        cli_mpi_abort(rc);
    thz_context_destroy(ctx); /* ends the other ranks' thz_mpi_serve_batch */
    thz_sequence_destroy(seq);
    return rc;
}
