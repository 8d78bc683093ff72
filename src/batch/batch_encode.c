/* Encoding a movie of brightness temperature with FFmpeg's libraries (Debian's
 * libavcodec, libavformat, libswscale): H.264 through libx264 in an MP4 (MPEG-4 part 2
 * where the libavcodec at hand has no libx264). Each frame is drawn here as RGB: the
 * image in the viridis colour map (its lightness rises with Tb, so a brighter pixel is
 * a warmer one), the frame time above it, and a colour bar with the scale's ends in K
 * at its right, in a 3x5 pixel font. One encoder thread and FFmpeg's bit-exact flags:
 * the same frames give the same file, byte for byte. The libraries are opened here, at
 * run time, for each movie (see movie_av).
 */
#include <dlfcn.h>
#include <errno.h>
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/macros.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "batch/batch_internal.h"
#include "core/alloc.h"
#include "core/error.h"
#include "core/path.h"

enum { MOVIE_MIN_WIDTH = 256, MOVIE_TOP = 16, MOVIE_BAR = 16, MOVIE_RIGHT = 96, MOVIE_GLYPH = 2 };

/* FFmpeg's functions, looked up at run time (dlopen) when a movie is made: linking
 * libavcodec would load its ~120 dependent libraries into every thzmap process (0.3 s
 * at each start), for a feature only `batch` uses. The headers fix the sonames. */
#define MOVIE_AV_FUNCTIONS(X)                                                                      \
    X(avutil, av_d2q)                                                                              \
    X(avutil, av_frame_alloc)                                                                      \
    X(avutil, av_frame_free)                                                                       \
    X(avutil, av_frame_get_buffer)                                                                 \
    X(avutil, av_frame_make_writable)                                                              \
    X(avutil, av_log_set_level)                                                                    \
    X(avutil, av_opt_set)                                                                          \
    X(avutil, av_strerror)                                                                         \
    X(avcodec, avcodec_alloc_context3)                                                             \
    X(avcodec, avcodec_find_encoder)                                                               \
    X(avcodec, avcodec_find_encoder_by_name)                                                       \
    X(avcodec, avcodec_free_context)                                                               \
    X(avcodec, avcodec_open2)                                                                      \
    X(avcodec, avcodec_parameters_from_context)                                                    \
    X(avcodec, avcodec_receive_packet)                                                             \
    X(avcodec, avcodec_send_frame)                                                                 \
    X(avcodec, av_packet_alloc)                                                                    \
    X(avcodec, av_packet_free)                                                                     \
    X(avcodec, av_packet_rescale_ts)                                                               \
    X(avformat, avformat_alloc_output_context2)                                                    \
    X(avformat, avformat_free_context)                                                             \
    X(avformat, avformat_new_stream)                                                               \
    X(avformat, avformat_write_header)                                                             \
    X(avformat, avio_closep)                                                                       \
    X(avformat, avio_open)                                                                         \
    X(avformat, av_interleaved_write_frame)                                                        \
    X(avformat, av_write_trailer)                                                                  \
    X(swscale, sws_getContext)                                                                     \
    X(swscale, sws_scale)                                                                          \
    X(swscale, sws_freeContext)

typedef struct movie_av {
    void *lib[4]; /* avutil, avcodec, avformat, swscale */
#define MOVIE_AV_MEMBER(so, name) __typeof__(&name) name;
    MOVIE_AV_FUNCTIONS(MOVIE_AV_MEMBER)
#undef MOVIE_AV_MEMBER
} movie_av;

enum { MOVIE_LIB_avutil, MOVIE_LIB_avcodec, MOVIE_LIB_avformat, MOVIE_LIB_swscale };

static const char *const movie_sonames[4] = {
    "libavutil.so." AV_STRINGIFY(LIBAVUTIL_VERSION_MAJOR),
    "libavcodec.so." AV_STRINGIFY(LIBAVCODEC_VERSION_MAJOR),
    "libavformat.so." AV_STRINGIFY(LIBAVFORMAT_VERSION_MAJOR),
    "libswscale.so." AV_STRINGIFY(LIBSWSCALE_VERSION_MAJOR)};

/* Forgets the libraries without closing them: FFmpeg's dependencies keep state from
 * their initialisers (allocations that would leak, and codecs registered once), so
 * they stay loaded for the process, as if linked; opening them again is cheap. */
static void movie_av_close(movie_av *av)
{
    memset(av, 0, sizeof *av);
}

/* Opens the four libraries and looks every function up; THZ_ERR_IO naming what is
 * missing (Debian: libavcodec59, libavformat59, libavutil57, libswscale6). */
static thz_status movie_av_open(movie_av *av, thz_error *err)
{
    memset(av, 0, sizeof *av);
    for (int i = 0; i < 4; i++) {
        av->lib[i] = dlopen(movie_sonames[i], RTLD_NOW | RTLD_LOCAL);
        if (!av->lib[i]) {
            const char *why = dlerror();
            movie_av_close(av);
            /* installing helps only where the library is missing, not where it could not
             * be mapped (out of address space: ulimit -v) */
            if (why && !strstr(why, "No such file"))
                return thz_error_set(err, THZ_ERR_IO, "movies: cannot load FFmpeg's %s: %s",
                                     movie_sonames[i], why);
            return thz_error_set(err, THZ_ERR_IO,
                                 "movies need FFmpeg's %s (Debian: libavcodec-dev, "
                                 "libavformat-dev, libswscale-dev): %s",
                                 movie_sonames[i], why ? why : "not found");
        }
    }
    void *p = NULL;
#define MOVIE_AV_LOOKUP(so, name)                                                                  \
    p = dlsym(av->lib[MOVIE_LIB_##so], #name);                                                     \
    if (!p) {                                                                                      \
        movie_av_close(av);                                                                        \
        return thz_error_set(err, THZ_ERR_IO, "%s: no function %s", movie_sonames[MOVIE_LIB_##so], \
                             #name);                                                               \
    }                                                                                              \
    memcpy(&av->name, &p, sizeof p);
    MOVIE_AV_FUNCTIONS(MOVIE_AV_LOOKUP)
#undef MOVIE_AV_LOOKUP
    return THZ_OK;
}

struct movie_writer {
    movie_av av;
    const char *codec_name;
    movie_spec spec;
    movie_layout layout;
    char tmp[THZ_PATH_MAX];
    AVFormatContext *fmt;
    AVCodecContext *codec;
    AVStream *stream;
    struct SwsContext *sws;
    AVFrame *frame;
    AVPacket *packet;
    uint8_t *rgb;
    int64_t pts;
    int file_open, finished;
};

/* viridis at 9 even stops (its lightness rises monotonically) */
static const unsigned char movie_viridis[9][3] = {{68, 1, 84},    {71, 44, 122},  {59, 81, 139},
                                                  {44, 113, 142}, {33, 144, 141}, {39, 173, 129},
                                                  {92, 200, 99},  {170, 220, 50}, {253, 231, 37}};

static void movie_colour(double x, uint8_t rgb[3])
{
    if (!isfinite(x)) {
        rgb[0] = rgb[1] = rgb[2] = 0;
        return;
    }
    x = fmin(1.0, fmax(0.0, x)) * 8.0;
    int i = (int)x < 8 ? (int)x : 7;
    double u = x - i;
    for (int k = 0; k < 3; k++)
        rgb[k] = (uint8_t)lrint((1.0 - u) * movie_viridis[i][k] + u * movie_viridis[i + 1][k]);
}

/* 3x5 glyphs, one row per 3 bits (top row first). */
static unsigned movie_glyph(char c)
{
    static const char chars[] = "0123456789.-=tsK";
    static const unsigned rows[][5] = {
        {7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {7, 1, 7, 4, 7}, {7, 1, 7, 1, 7},
        {5, 5, 7, 1, 1}, {7, 4, 7, 1, 7}, {7, 4, 7, 5, 7}, {7, 1, 1, 1, 1},
        {7, 5, 7, 5, 7}, {7, 5, 7, 1, 7}, {0, 0, 0, 0, 2}, {0, 0, 7, 0, 0},
        {0, 7, 0, 7, 0}, {2, 7, 2, 2, 1}, {3, 4, 2, 1, 6}, {5, 6, 4, 6, 5}};
    const char *p = strchr(chars, c);
    if (!p || !c)
        return 0;
    const unsigned *r = rows[p - chars];
    return r[0] << 12 | r[1] << 9 | r[2] << 6 | r[3] << 3 | r[4];
}

static void movie_text(const movie_writer *m, uint32_t x, uint32_t y, const char *text)
{
    const movie_layout *l = &m->layout;
    for (; *text; text++, x += 4 * MOVIE_GLYPH) {
        unsigned g = movie_glyph(*text);
        for (uint32_t r = 0; r < 5 * MOVIE_GLYPH; r++)
            for (uint32_t c = 0; c < 3 * MOVIE_GLYPH; c++) {
                unsigned bit = 14u - (r / MOVIE_GLYPH) * 3u - c / MOVIE_GLYPH;
                if (!(g >> bit & 1u) || x + c >= l->width || y + r >= l->height)
                    continue;
                uint8_t *p = &m->rgb[((size_t)(y + r) * l->width + x + c) * 3];
                p[0] = p[1] = p[2] = 230;
            }
    }
}

void movie_layout_of(uint32_t columns, uint32_t rows, movie_layout *out)
{
    uint32_t pixel = columns >= MOVIE_MIN_WIDTH ? 1 : (MOVIE_MIN_WIDTH + columns - 1) / columns;
    if (pixel > 16)
        pixel = 16;
    uint32_t h = MOVIE_TOP + rows * pixel;
    if (h < MOVIE_TOP + 64)
        h = MOVIE_TOP + 64; /* room for the bar's labels */
    *out = (movie_layout){.pixel = pixel,
                          .image_x = 0,
                          .image_y = MOVIE_TOP,
                          .width = (columns * pixel + MOVIE_RIGHT + 1) & ~1u,
                          .height = (h + 1) & ~1u};
}

int movie_time_decimals(double dt)
{
    if (!(dt > 0.0) || !isfinite(dt))
        return 2;
    int d0 = (int)ceil(-log10(dt) - 1e-9);
    d0 = d0 > 0 ? d0 : 0;
    for (int d = d0; d <= d0 + 2; d++) {
        double scaled = dt * pow(10.0, d);
        if (fabs(scaled - round(scaled)) <= 1e-9 * scaled)
            return d;
    }
    return d0;
}

/* Draws frame tb (K) into m->rgb. */
static void movie_draw(movie_writer *m, const float *tb, double time_s)
{
    const movie_layout *l = &m->layout;
    const movie_spec *s = &m->spec;
    memset(m->rgb, 24, (size_t)l->width * l->height * 3);
    double span = s->tb_max_k - s->tb_min_k;
    for (uint32_t r = 0; r < s->rows * l->pixel; r++)
        for (uint32_t c = 0; c < s->columns * l->pixel; c++) {
            float v = tb[(size_t)(r / l->pixel) * s->columns + c / l->pixel];
            double x = span > 0.0 ? ((double)v - s->tb_min_k) / span : 0.5;
            movie_colour(x, &m->rgb[((size_t)(l->image_y + r) * l->width + l->image_x + c) * 3]);
        }
    /* the bar: top = max, bottom = min, between the image's top and the frame's bottom */
    uint32_t bx = s->columns * l->pixel + 8, top = l->image_y + 6, bottom = l->height - 8;
    for (uint32_t y = top; y < bottom; y++)
        for (uint32_t x = bx; x < bx + MOVIE_BAR; x++)
            movie_colour((double)(bottom - 1 - y) / (double)(bottom - 1 - top),
                         &m->rgb[((size_t)y * l->width + x) * 3]);
    /* a space before the unit ("300.0 K", "t = 0.25 s") where the text fits the frame's
     * width, else without; the time's decimals those of the frame interval (fps up to
     * 1000: 0.001 s) */
    char text[48];
    uint32_t lx = bx + MOVIE_BAR + 4;
    const double ends[2] = {s->tb_max_k, s->tb_min_k};
    const uint32_t ys[2] = {top, bottom - 5 * MOVIE_GLYPH};
    for (int e = 0; e < 2; e++) {
        snprintf(text, sizeof text, "%.1f K", ends[e]);
        if (lx + strlen(text) * 4 * MOVIE_GLYPH > l->width)
            snprintf(text, sizeof text, "%.1fK", ends[e]);
        movie_text(m, lx, ys[e], text);
    }
    int d = movie_time_decimals(s->frame_interval_s > 0.0 ? s->frame_interval_s : 1.0 / s->fps);
    snprintf(text, sizeof text, "t = %.*f s", d, time_s);
    if (2 + strlen(text) * 4 * MOVIE_GLYPH > l->width)
        snprintf(text, sizeof text, "t=%.*fs", d, time_s);
    movie_text(m, 2, 3, text);
}

static thz_status movie_av_error(const movie_writer *m, thz_error *err, const char *path,
                                 const char *what, int code)
{
    char buf[AV_ERROR_MAX_STRING_SIZE] = "";
    m->av.av_strerror(code, buf, sizeof buf);
    return thz_error_set(err, THZ_ERR_IO, "%s: %s: %s", path, what, buf);
}

/* Sends frame (NULL: flush) and writes the packets the encoder gives back. */
static thz_status movie_encode(movie_writer *m, AVFrame *frame, thz_error *err)
{
    int rc = m->av.avcodec_send_frame(m->codec, frame);
    if (rc < 0)
        return movie_av_error(m, err, m->spec.path, "encoding failed", rc);
    for (;;) {
        rc = m->av.avcodec_receive_packet(m->codec, m->packet);
        if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF)
            return THZ_OK;
        if (rc < 0)
            return movie_av_error(m, err, m->spec.path, "encoding failed", rc);
        m->av.av_packet_rescale_ts(m->packet, m->codec->time_base, m->stream->time_base);
        m->packet->stream_index = m->stream->index;
        rc = m->av.av_interleaved_write_frame(m->fmt, m->packet);
        if (rc < 0)
            return movie_av_error(m, err, m->spec.path, "cannot write", rc);
    }
}

static const AVCodec *movie_find_codec(const movie_av *av)
{
    const AVCodec *c = av->avcodec_find_encoder_by_name("libx264");
    return c ? c : av->avcodec_find_encoder(AV_CODEC_ID_MPEG4);
}

/* Probed with this libavcodec (59) and libx264 (164): x264 refuses a width or height
 * above 16384 ("invalid width x height"), MPEG-4 part 2 one of 8192 or more ("dimensions
 * too large for MPEG-4"; its sizes are 13-bit), whose largest even size is 8190. */
enum { MOVIE_MAX_SIDE_X264 = 16384, MOVIE_MAX_SIDE_MPEG4 = 8190 };

int movie_fits(uint32_t columns, uint32_t rows, movie_limit *out)
{
    movie_layout l;
    movie_layout_of(columns, rows, &l);
    *out = (movie_limit){.width = l.width,
                         .height = l.height,
                         .max_side = MOVIE_MAX_SIDE_MPEG4,
                         .codec = "MPEG-4 part 2"};
    if (l.width <= MOVIE_MAX_SIDE_MPEG4 && l.height <= MOVIE_MAX_SIDE_MPEG4)
        return 1; /* within every encoder's: no need to open FFmpeg to know which */
    movie_av av;
    thz_error ignored;
    /* without FFmpeg there is no movie either way; movie_open says why */
    if (movie_av_open(&av, &ignored) != THZ_OK ||
        av.avcodec_find_encoder_by_name("libx264") != NULL) {
        out->max_side = MOVIE_MAX_SIDE_X264;
        out->codec = "libx264";
    }
    movie_av_close(&av);
    return l.width <= out->max_side && l.height <= out->max_side;
}

thz_status movie_open(const movie_spec *spec, movie_writer **out, thz_error *err)
{
    *out = NULL;
    movie_writer *m = thz_calloc(1, sizeof *m);
    if (!m)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    m->spec = *spec;
    movie_layout_of(spec->columns, spec->rows, &m->layout);
    const char *slash = strrchr(spec->path, '/');
    int dir_len = slash ? (int)(slash - spec->path) + 1 : 0;
    if (snprintf(m->tmp, sizeof m->tmp, "%.*s.%s.part", dir_len, spec->path,
                 slash ? slash + 1 : spec->path) >= (int)sizeof m->tmp) {
        free(m);
        return thz_error_set(err, THZ_ERR_IO, "%s: path too long", spec->path);
    }
    *out = m;
    thz_status st = movie_av_open(&m->av, err);
    if (st != THZ_OK)
        return st;
    /* The library never prints: FFmpeg's log (process-wide, its own) stays silent; its
     * errors reach the caller through the return codes. */
    m->av.av_log_set_level(AV_LOG_QUIET);
    const AVCodec *codec = movie_find_codec(&m->av);
    if (!codec)
        return thz_error_set(err, THZ_ERR_IO, "%s: libavcodec has neither libx264 nor MPEG-4",
                             spec->path);
    m->codec_name = codec->name;
    int rc = m->av.avformat_alloc_output_context2(&m->fmt, NULL, "mp4", m->tmp);
    if (rc < 0 || !m->fmt)
        return movie_av_error(m, err, spec->path, "no MP4 muxer", rc);
    m->fmt->flags |= AVFMT_FLAG_BITEXACT;
    m->stream = m->av.avformat_new_stream(m->fmt, NULL);
    m->codec = m->av.avcodec_alloc_context3(codec);
    m->frame = m->av.av_frame_alloc();
    m->packet = m->av.av_packet_alloc();
    /* with FFmpeg's padding after the pixels, zeroed: swscale reads its input in vector-
     * wide loads, past the last row's end (valgrind saw 4 bytes read beyond) */
    m->rgb = thz_calloc(
        (size_t)m->layout.width * m->layout.height * 3 + AV_INPUT_BUFFER_PADDING_SIZE, 1);
    if (!m->stream || !m->codec || !m->frame || !m->packet || !m->rgb)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", spec->path);
    AVCodecContext *c = m->codec;
    c->width = (int)m->layout.width;
    c->height = (int)m->layout.height;
    c->pix_fmt = AV_PIX_FMT_YUV420P;
    c->framerate = m->av.av_d2q(spec->fps, 100000);
    c->time_base = av_inv_q(c->framerate);
    c->gop_size = 25;
    c->max_b_frames = 0;
    c->thread_count = 1;
    c->flags |= AV_CODEC_FLAG_BITEXACT;
    if (m->fmt->oformat->flags & AVFMT_GLOBALHEADER)
        c->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    if (codec->id == AV_CODEC_ID_H264) {
        m->av.av_opt_set(c->priv_data, "preset", "medium", 0);
        m->av.av_opt_set(c->priv_data, "crf", "18", 0);
    } else {
        c->flags |= AV_CODEC_FLAG_QSCALE;
        c->global_quality = FF_QP2LAMBDA * 3;
    }
    rc = m->av.avcodec_open2(c, codec, NULL);
    if (rc < 0)
        return movie_av_error(m, err, spec->path, "cannot open the encoder", rc);
    rc = m->av.avcodec_parameters_from_context(m->stream->codecpar, c);
    if (rc < 0)
        return movie_av_error(m, err, spec->path, "encoder parameters", rc);
    m->stream->time_base = c->time_base;
    m->stream->avg_frame_rate = c->framerate;
    m->frame->format = c->pix_fmt;
    m->frame->width = c->width;
    m->frame->height = c->height;
    rc = m->av.av_frame_get_buffer(m->frame, 0);
    if (rc < 0)
        return movie_av_error(m, err, spec->path, "frame buffer", rc);
    m->sws = m->av.sws_getContext(c->width, c->height, AV_PIX_FMT_RGB24, c->width, c->height,
                                  AV_PIX_FMT_YUV420P, SWS_POINT | SWS_BITEXACT | SWS_ACCURATE_RND,
                                  NULL, NULL, NULL);
    if (!m->sws)
        return thz_error_set(err, THZ_ERR_IO, "%s: no RGB to YUV conversion", spec->path);
    rc = m->av.avio_open(&m->fmt->pb, m->tmp, AVIO_FLAG_WRITE);
    if (rc < 0)
        return movie_av_error(m, err, m->spec.path, "cannot create", rc);
    m->file_open = 1;
    rc = m->av.avformat_write_header(m->fmt, NULL);
    if (rc < 0)
        return movie_av_error(m, err, m->spec.path, "cannot write", rc);
    return THZ_OK;
}

thz_status movie_add_frame(movie_writer *m, const float *tb, double time_s, thz_error *err)
{
    movie_draw(m, tb, time_s);
    int rc = m->av.av_frame_make_writable(m->frame);
    if (rc < 0)
        return movie_av_error(m, err, m->spec.path, "frame buffer", rc);
    const uint8_t *src[1] = {m->rgb};
    const int stride[1] = {(int)m->layout.width * 3};
    m->av.sws_scale(m->sws, src, stride, 0, (int)m->layout.height, m->frame->data,
                    m->frame->linesize);
    m->frame->pts = m->pts++;
    return movie_encode(m, m->frame, err);
}

thz_status movie_finish(movie_writer *m, thz_error *err)
{
    thz_status st = movie_encode(m, NULL, err);
    int rc = st == THZ_OK ? m->av.av_write_trailer(m->fmt) : 0;
    if (st == THZ_OK && rc < 0)
        st = movie_av_error(m, err, m->spec.path, "cannot write", rc);
    rc = m->av.avio_closep(&m->fmt->pb);
    m->file_open = 0;
    if (st == THZ_OK && rc < 0)
        st = movie_av_error(m, err, m->spec.path, "cannot write", rc);
    if (st == THZ_OK && rename(m->tmp, m->spec.path) != 0)
        st = thz_error_set(err, THZ_ERR_IO, "%s: cannot rename into place: %s", m->spec.path,
                           strerror(errno));
    m->finished = st == THZ_OK;
    return st;
}

void movie_destroy(movie_writer *m)
{
    if (!m)
        return;
    if (m->fmt && m->file_open)
        m->av.avio_closep(&m->fmt->pb);
    if (!m->finished && m->fmt)
        unlink(m->tmp);
    if (!m->av.lib[0]) { /* FFmpeg was never loaded: nothing of it to free */
        free(m->rgb);
        free(m);
        return;
    }
    m->av.sws_freeContext(m->sws);
    m->av.av_frame_free(&m->frame);
    m->av.av_packet_free(&m->packet);
    m->av.avcodec_free_context(&m->codec);
    m->av.avformat_free_context(m->fmt);
    movie_av_close(&m->av);
    free(m->rgb);
    free(m);
}

const char *movie_codec(const movie_writer *m)
{
    return m && m->codec_name ? m->codec_name : "none";
}
