/* PNG via libpng (into memory, then one atomic write), PGM/PPM raw or in zstd, and PFM. */
#define _POSIX_C_SOURCE 200809L
#include "image_io.h"

#include <errno.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h> /* Z_RLE */
#include <zstd.h>

struct mem_sink {
    uint8_t *data;
    size_t len, cap;
    int failed;
};

static void sink_write(png_structp png, png_bytep bytes, png_size_t len)
{
    struct mem_sink *s = png_get_io_ptr(png);
    if (s->failed)
        return;
    if (s->len + len > s->cap) {
        size_t cap = (s->len + len) * 2;
        uint8_t *d = realloc(s->data, cap);
        if (d == NULL) {
            s->failed = 1;
            return;
        }
        s->data = d;
        s->cap = cap;
    }
    memcpy(s->data + s->len, bytes, len);
    s->len += len;
}

static void sink_flush(png_structp png)
{
    (void)png;
}

int image_write_png(const struct hal_storage *st, const char *path, const uint8_t *pixels,
                    uint32_t width, uint32_t height, int channels)
{
    struct mem_sink sink = {0};
    int rc = -ENOMEM;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (png == NULL || info == NULL)
        goto out_png;
    if (setjmp(png_jmpbuf(png))) {
        rc = -EIO;
        goto out_png;
    }
    png_set_write_fn(png, &sink, sink_write, sink_flush);
    /* Fast compression: captures are many and large; the files stay lossless. The Up filter and
     * run-length zlib: half the time of adaptive filtering and smaller on camera frames (make
     * bench's frame table). */
    png_set_compression_level(png, 1);
    png_set_compression_strategy(png, Z_RLE);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
    png_set_IHDR(png, info, width, height, 8,
                 channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (uint32_t y = 0; y < height; y++)
        png_write_row(png, (png_const_bytep)(pixels + (size_t)y * width * (size_t)channels));
    png_write_end(png, NULL);
    rc = sink.failed ? -ENOMEM : hal_storage_write_file(st, path, sink.data, sink.len);
out_png:
    png_destroy_write_struct(&png, &info);
    free(sink.data);
    return rc;
}

int image_read_png(const char *path, uint8_t *pixels, size_t capacity, uint32_t *width,
                   uint32_t *height, int channels, char *why, size_t why_len)
{
    png_image img;
    memset(&img, 0, sizeof(img));
    img.version = PNG_IMAGE_VERSION;
    errno = 0;
    if (!png_image_begin_read_from_file(&img, path)) {
        int missing = errno == ENOENT;
        snprintf(why, why_len, "%s", missing ? strerror(ENOENT) : img.message);
        png_image_free(&img);
        return missing ? -ENOENT : -EINVAL;
    }
    int rc = -EINVAL;
    if (img.format & PNG_FORMAT_FLAG_LINEAR)
        snprintf(why, why_len, "a 16-bit PNG; frames are 8-bit");
    else if (img.format & PNG_FORMAT_FLAG_ALPHA)
        snprintf(why, why_len, "a PNG with an alpha channel; frames are grey or RGB");
    else
        rc = 0;
    img.format = channels == 3 ? PNG_FORMAT_RGB : PNG_FORMAT_GRAY;
    if (rc == 0 && PNG_IMAGE_SIZE(img) > capacity) {
        snprintf(why, why_len, "%ux%u, larger than the compiled frame limit", (unsigned)img.width,
                 (unsigned)img.height);
        rc = -EINVAL;
    }
    if (rc == 0 && !png_image_finish_read(&img, NULL, pixels, 0, NULL)) {
        snprintf(why, why_len, "%s", img.message); /* libpng's words: truncated, bad CRC, ... */
        rc = -EINVAL;
    }
    png_image_free(&img);
    if (rc == 0) {
        *width = img.width;
        *height = img.height;
    }
    return rc;
}

int image_write_pfm(const struct hal_storage *st, const char *path, const float *pixels,
                    uint32_t width, uint32_t height, int channels)
{
    char header[64];
    /* Negative scale = little-endian; PFM stores rows bottom to top. */
    int hl = snprintf(header, sizeof(header), "%s\n%u %u\n-1.0\n", channels == 3 ? "PF" : "Pf",
                      (unsigned)width, (unsigned)height);
    size_t row = (size_t)width * (size_t)channels * sizeof(float);
    size_t len = (size_t)hl + row * height;
    uint8_t *buf = malloc(len);
    if (buf == NULL)
        return -ENOMEM;
    memcpy(buf, header, (size_t)hl);
    for (uint32_t y = 0; y < height; y++)
        memcpy(buf + hl + row * y, pixels + (size_t)(height - 1 - y) * width * (size_t)channels,
               row);
    int rc = hal_storage_write_file(st, path, buf, len);
    free(buf);
    return rc;
}

/* ---- PGM/PPM, raw or as one zstd frame ---- */

int image_write_pnm(const struct hal_storage *st, const char *path, const uint8_t *pixels,
                    uint32_t width, uint32_t height, int channels, int zstd_level)
{
    char header[48];
    int hl = snprintf(header, sizeof(header), "P%c\n%u %u\n255\n", channels == 3 ? '6' : '5',
                      (unsigned)width, (unsigned)height);
    size_t n = (size_t)width * height * (size_t)channels;
    struct hal_file f;
    int rc = hal_storage_open(st, &f, path);
    if (rc != 0)
        return rc;
    if (zstd_level == 0) { /* the bytes as they are: no copy */
        rc = hal_storage_write(st, &f, header, (size_t)hl);
        if (rc == 0)
            rc = hal_storage_write(st, &f, pixels, n);
        goto out_commit;
    }
    /* One zstd frame of header and pixels, with its content size so that readers can size their
     * buffer; the two inputs streamed in so that the pixels are not copied. */
    size_t cap = ZSTD_compressBound((size_t)hl + n);
    uint8_t *out = malloc(cap);
    ZSTD_CCtx *cctx = ZSTD_createCCtx();
    rc = -ENOMEM;
    if (out == NULL || cctx == NULL)
        goto out_free;
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_compressionLevel, zstd_level);
    ZSTD_CCtx_setPledgedSrcSize(cctx, (unsigned long long)hl + n);
    ZSTD_outBuffer o = {out, cap, 0};
    ZSTD_inBuffer in_header = {header, (size_t)hl, 0}, in_pixels = {pixels, n, 0};
    size_t z = ZSTD_compressStream2(cctx, &o, &in_header, ZSTD_e_continue);
    while (!ZSTD_isError(z) && (z = ZSTD_compressStream2(cctx, &o, &in_pixels, ZSTD_e_end)) != 0 &&
           !ZSTD_isError(z))
        ;
    rc = ZSTD_isError(z) ? -EIO : hal_storage_write(st, &f, out, o.pos);
out_free:
    ZSTD_freeCCtx(cctx);
    free(out);
out_commit:
    if (rc == 0)
        return hal_storage_commit(st, &f);
    hal_storage_abort(st, &f);
    return rc;
}

/* The whole file in memory, decompressed when it is a zstd frame. @p why on failure. */
static int read_whole(const char *path, uint8_t **data, size_t *len, char *why, size_t why_len)
{
    FILE *fp = fopen(path, "rb");
    if (fp == NULL) {
        int rc = -errno;
        snprintf(why, why_len, "%s", strerror(-rc));
        return rc;
    }
    int rc = -EINVAL;
    uint8_t *raw = NULL, *plain = NULL;
    long size = fseek(fp, 0, SEEK_END) == 0 ? ftell(fp) : -1;
    if (size < 0 || fseek(fp, 0, SEEK_SET) != 0 || (raw = malloc((size_t)size + 1)) == NULL ||
        fread(raw, 1, (size_t)size, fp) != (size_t)size) {
        snprintf(why, why_len, "cannot read it");
        goto out_close;
    }
    if (size < 4 || ZSTD_getFrameContentSize(raw, (size_t)size) == ZSTD_CONTENTSIZE_ERROR) {
        *data = raw; /* not zstd: the file itself */
        *len = (size_t)size;
        raw = NULL;
        rc = 0;
        goto out_close;
    }
    unsigned long long plain_len = ZSTD_getFrameContentSize(raw, (size_t)size);
    /* no frame is larger than the compiled limit, and a header claiming more is not believed */
    if (plain_len == ZSTD_CONTENTSIZE_UNKNOWN || plain_len > (size_t)HAL_MAX_PIXELS * 3 + 64 ||
        (plain = malloc((size_t)plain_len + 1)) == NULL) {
        snprintf(why, why_len, "a zstd frame of unknown or too large size");
        goto out_close;
    }
    size_t z = ZSTD_decompress(plain, (size_t)plain_len, raw, (size_t)size);
    if (ZSTD_isError(z) || z != plain_len) {
        snprintf(why, why_len, "damaged zstd data (%s)",
                 ZSTD_isError(z) ? ZSTD_getErrorName(z) : "short");
        free(plain);
        goto out_close;
    }
    *data = plain;
    *len = z;
    rc = 0;
out_close:
    free(raw);
    fclose(fp);
    return rc;
}

/* Width, height, channels and the offset of the pixels of a binary PGM/PPM of maxval 255. */
static int parse_pnm(const uint8_t *d, size_t len, uint32_t *w, uint32_t *h, int *channels,
                     size_t *offset)
{
    unsigned vals[3];
    size_t i = 2;
    if (len < 2 || d[0] != 'P' || (d[1] != '5' && d[1] != '6'))
        return -EINVAL;
    for (int k = 0; k < 3; k++) {
        while (i < len && (d[i] == ' ' || d[i] == '\t' || d[i] == '\r' || d[i] == '\n' ||
                           d[i] == '#')) {
            if (d[i] == '#') /* a comment runs to the end of its line */
                while (i < len && d[i] != '\n')
                    i++;
            else
                i++;
        }
        unsigned long v = 0;
        size_t start = i;
        while (i < len && d[i] >= '0' && d[i] <= '9' && v < 100000)
            v = v * 10 + (unsigned long)(d[i++] - '0');
        if (i == start || v == 0 || v >= 100000)
            return -EINVAL;
        vals[k] = (unsigned)v;
    }
    if (i >= len || vals[2] != 255) /* one whitespace byte, then the pixels */
        return -EINVAL;
    *w = vals[0];
    *h = vals[1];
    *channels = d[1] == '6' ? 3 : 1;
    *offset = i + 1;
    return 0;
}

int image_read_pnm(const char *path, uint8_t *pixels, size_t capacity, uint32_t *width,
                   uint32_t *height, int channels, char *why, size_t why_len)
{
    uint8_t *d = NULL;
    size_t len = 0, offset = 0;
    uint32_t w = 0, h = 0;
    int have = 0;
    int rc = read_whole(path, &d, &len, why, why_len);
    if (rc != 0)
        return rc;
    rc = -EINVAL;
    if (parse_pnm(d, len, &w, &h, &have, &offset) != 0)
        snprintf(why, why_len, "not an 8-bit binary PGM or PPM");
    else if (len - offset < (size_t)w * h * (size_t)have)
        snprintf(why, why_len, "truncated: %zu bytes of pixels for %ux%u", len - offset,
                 (unsigned)w, (unsigned)h);
    else if (have == 3 && channels == 1)
        snprintf(why, why_len, "an RGB frame where a grey one belongs");
    else if ((size_t)w * h * (size_t)channels > capacity)
        snprintf(why, why_len, "%ux%u, larger than the compiled frame limit", (unsigned)w,
                 (unsigned)h);
    else
        rc = 0;
    if (rc == 0 && have == channels)
        memcpy(pixels, d + offset, (size_t)w * h * (size_t)channels);
    else if (rc == 0) /* grey to RGB */
        for (size_t i = 0; i < (size_t)w * h; i++)
            memset(pixels + 3 * i, d[offset + i], 3);
    if (rc == 0) {
        *width = w;
        *height = h;
    }
    free(d);
    return rc;
}
