/* Frame encodings side by side (issue 17): bytes per view and encode/decode time of one view's
 * frames as the scan keeps them (patterns grey, colour frames RGB), rendered by the simulator.
 * In memory, so the numbers are the codec's, not the disk's. make bench. */
#define _POSIX_C_SOURCE 200809L
#include "decode.h"
#include "gray.h"
#include "scan.h"
#include "test_util.h"

#include <png.h>
#include <spng.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <zlib.h>
#include <zstd.h>

#define COLOUR_FRAMES 6 /* white, all lights, four lights alone: config/sim.ini's colour set */
#define REPEAT 3

struct frame {
    uint8_t *pixels;
    uint32_t channels;
};

static struct frame frames[DECODE_MAX_PATTERNS + COLOUR_FRAMES];
static uint32_t frame_count, width, height;
static uint8_t *encoded[DECODE_MAX_PATTERNS + COLOUR_FRAMES];
static size_t encoded_len[DECODE_MAX_PATTERNS + COLOUR_FRAMES], encoded_cap;
static uint8_t *decoded;

static double cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

/* ---- libpng (what the scan directory used up to now: adaptive filters) ---- */

struct sink {
    uint8_t *data;
    size_t len, cap;
};

static void sink_write(png_structp png, png_bytep bytes, png_size_t len)
{
    struct sink *s = png_get_io_ptr(png);
    if (s->len + len <= s->cap)
        memcpy(s->data + s->len, bytes, len);
    s->len += len;
}

static void sink_flush(png_structp png)
{
    (void)png;
}

static size_t libpng_encode(const struct frame *f, uint8_t *out, size_t cap, int filters,
                            int strategy)
{
    struct sink sink = {.data = out, .cap = cap};
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return 0;
    }
    png_set_write_fn(png, &sink, sink_write, sink_flush);
    png_set_compression_level(png, 1);
    png_set_compression_strategy(png, strategy);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, filters);
    png_set_IHDR(png, info, width, height, 8,
                 f->channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (uint32_t y = 0; y < height; y++)
        png_write_row(png, f->pixels + (size_t)y * width * f->channels);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    return sink.len <= cap ? sink.len : 0;
}

static int libpng_decode(const uint8_t *in, size_t len, const struct frame *f)
{
    png_image img;
    memset(&img, 0, sizeof(img));
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&img, in, len))
        return -1;
    img.format = f->channels == 3 ? PNG_FORMAT_RGB : PNG_FORMAT_GRAY;
    int ok = png_image_finish_read(&img, NULL, decoded, 0, NULL);
    png_image_free(&img);
    return ok ? 0 : -1;
}

static size_t png_adaptive(const struct frame *f, uint8_t *o, size_t c)
{
    return libpng_encode(f, o, c, PNG_ALL_FILTERS, Z_DEFAULT_STRATEGY);
}
static size_t png_up_rle(const struct frame *f, uint8_t *o, size_t c)
{
    return libpng_encode(f, o, c, PNG_FILTER_UP, Z_RLE);
}

/* ---- libspng ---- */

static size_t spng_encode(const struct frame *f, uint8_t *out, size_t cap)
{
    spng_ctx *ctx = spng_ctx_new(SPNG_CTX_ENCODER);
    struct spng_ihdr ihdr = {.width = width,
                             .height = height,
                             .bit_depth = 8,
                             .color_type = f->channels == 3 ? SPNG_COLOR_TYPE_TRUECOLOR
                                                            : SPNG_COLOR_TYPE_GRAYSCALE};
    size_t len = 0;
    int err = 0;
    spng_set_option(ctx, SPNG_ENCODE_TO_BUFFER, 1);
    spng_set_option(ctx, SPNG_IMG_COMPRESSION_LEVEL, 1);
    spng_set_option(ctx, SPNG_IMG_COMPRESSION_STRATEGY, Z_RLE);
    spng_set_option(ctx, SPNG_FILTER_CHOICE, SPNG_FILTER_CHOICE_UP);
    spng_set_ihdr(ctx, &ihdr);
    if (spng_encode_image(ctx, f->pixels, (size_t)width * height * f->channels, SPNG_FMT_PNG,
                          SPNG_ENCODE_FINALIZE) == 0) {
        uint8_t *png = spng_get_png_buffer(ctx, &len, &err);
        if (png != NULL && len <= cap)
            memcpy(out, png, len);
        else
            len = 0;
        free(png);
    }
    spng_ctx_free(ctx);
    return len;
}

static int spng_decode(const uint8_t *in, size_t len, const struct frame *f)
{
    spng_ctx *ctx = spng_ctx_new(0);
    spng_set_png_buffer(ctx, in, len);
    /* spng has no grey output format but its own (G8 is for grey files) */
    int rc = spng_decode_image(ctx, decoded, (size_t)width * height * f->channels,
                               f->channels == 3 ? SPNG_FMT_RGB8 : SPNG_FMT_G8, 0);
    spng_ctx_free(ctx);
    return rc == 0 ? 0 : -1;
}

/* ---- raw PGM/PPM, and the same bytes zstd-compressed ---- */

static size_t pnm_encode(const struct frame *f, uint8_t *out, size_t cap)
{
    int hl = snprintf((char *)out, cap, "P%c\n%u %u\n255\n", f->channels == 3 ? '6' : '5',
                      (unsigned)width, (unsigned)height);
    size_t n = (size_t)width * height * f->channels;
    if ((size_t)hl + n > cap)
        return 0;
    memcpy(out + hl, f->pixels, n);
    return (size_t)hl + n;
}

static int pnm_decode(const uint8_t *in, size_t len, const struct frame *f)
{
    size_t n = (size_t)width * height * f->channels;
    if (len < n)
        return -1;
    memcpy(decoded, in + len - n, n);
    return 0;
}

static size_t zstd_level(const struct frame *f, uint8_t *out, size_t cap, int level)
{
    size_t n = ZSTD_compress(out, cap, f->pixels, (size_t)width * height * f->channels, level);
    return ZSTD_isError(n) ? 0 : n;
}
static size_t zstd_encode(const struct frame *f, uint8_t *out, size_t cap)
{
    return zstd_level(f, out, cap, 1);
}
static size_t zstd_fast3(const struct frame *f, uint8_t *out, size_t cap)
{
    return zstd_level(f, out, cap, -3);
}

static int zstd_decode(const uint8_t *in, size_t len, const struct frame *f)
{
    size_t n = ZSTD_decompress(decoded, (size_t)width * height * f->channels, in, len);
    return ZSTD_isError(n) ? -1 : 0;
}

struct codec {
    const char *name;
    size_t (*encode)(const struct frame *f, uint8_t *out, size_t cap);
    int (*decode)(const uint8_t *in, size_t len, const struct frame *f);
};

static const struct codec codecs[] = {
    {"PNG, libpng, zlib 1, adaptive filters (until now)", png_adaptive, libpng_decode},
    {"PNG, libpng, zlib 1 RLE, filter Up (frame_format = png)", png_up_rle, libpng_decode},
    {"PNG, libspng, zlib 1 RLE, filter Up", spng_encode, spng_decode},
    {"PGM/PPM, raw (frame_format = pnm)", pnm_encode, pnm_decode},
    {"**PGM/PPM in zstd 1 (frame_format = zstd, the default)**", zstd_encode, zstd_decode},
    {"PGM/PPM in zstd -3", zstd_fast3, zstd_decode},
};

static int render_view(const char *config, struct test_rig *t)
{
    if (test_rig_load(t, config) != 0 || test_rig_start(t) != 0)
        return -1;
    struct sim_rig *rig = sim_ctl_rig();
    width = rig->width;
    height = rig->height;
    size_t pixels = (size_t)width * height;
    uint32_t patterns = gray_pattern_count(gray_bits_for_width(t->calib.proj_width));
    uint8_t *rgb = malloc(pixels * 3);
    if (rgb == NULL)
        return -1;
    sim_rig_update(rig);
    for (uint32_t i = 0; i < patterns + COLOUR_FRAMES; i++) {
        int colour = i >= patterns;
        uint32_t k = i - patterns;
        struct sim_sources src = {.projector_on = !colour || k == 0,
                                  .pattern_index = colour ? 0 : i,
                                  .lights_mask = !colour || k == 0 ? 0
                                                 : k == 1          ? 0xfu
                                                                   : 1u << (k - 2),
                                  .exposure_us = t->cfg.camera.exposure_us,
                                  .gain_milli = 1000};
        sim_rig_render(rig, &src, i, rgb);
        frames[i].channels = colour ? 3 : 1;
        frames[i].pixels = malloc(pixels * frames[i].channels);
        if (frames[i].pixels == NULL)
            return -1;
        if (colour)
            memcpy(frames[i].pixels, rgb, pixels * 3);
        else
            decode_rgb_to_grey(rgb, frames[i].pixels, pixels, 255);
    }
    frame_count = patterns + COLOUR_FRAMES;
    free(rgb);
    return 0;
}

int main(int argc, char **argv)
{
    static struct test_rig t;
    if (render_view(argc > 1 ? argv[1] : "config/sim.ini", &t) != 0)
        return 1;
    encoded_cap = (size_t)width * height * 3 + (size_t)height * 4 + 4096;
    decoded = malloc(encoded_cap);
    for (uint32_t i = 0; i < frame_count; i++)
        encoded[i] = malloc(encoded_cap);
    if (decoded == NULL)
        return 1;
    printf("one view's frames as kept: %u grey patterns and %d RGB colour frames, %ux%u "
           "(best of %d, one core, in memory)\n",
           (unsigned)(frame_count - COLOUR_FRAMES), COLOUR_FRAMES, (unsigned)width,
           (unsigned)height, REPEAT);
    printf("| encoding | MB per view | encode ms per view | decode ms per view |\n"
           "|---|---|---|---|\n");
    for (size_t c = 0; c < sizeof(codecs) / sizeof(codecs[0]); c++) {
        double best_enc = 1e30, best_dec = 1e30;
        size_t bytes = 0;
        for (int r = 0; r < REPEAT; r++) {
            double t0 = cpu_ms();
            bytes = 0;
            for (uint32_t i = 0; i < frame_count; i++) {
                encoded_len[i] = codecs[c].encode(&frames[i], encoded[i], encoded_cap);
                bytes += encoded_len[i];
            }
            double t1 = cpu_ms();
            for (uint32_t i = 0; i < frame_count; i++) {
                size_t n = (size_t)width * height * frames[i].channels;
                if (encoded_len[i] == 0 ||
                    codecs[c].decode(encoded[i], encoded_len[i], &frames[i]) != 0 ||
                    memcmp(decoded, frames[i].pixels, n) != 0) {
                    fprintf(stderr, "%s: frame %u does not come back as it was\n", codecs[c].name,
                            (unsigned)i);
                    return 1;
                }
            }
            double t2 = cpu_ms();
            best_enc = t1 - t0 < best_enc ? t1 - t0 : best_enc;
            best_dec = t2 - t1 < best_dec ? t2 - t1 : best_dec;
        }
        printf("| %s | %.1f | %.0f | %.0f |\n", codecs[c].name, (double)bytes / 1e6, best_enc,
               best_dec);
    }
    test_rig_stop(&t);
    return 0;
}
