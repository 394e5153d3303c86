/* PNG via libpng (into memory, then one atomic write) and PFM writers. */
#define _POSIX_C_SOURCE 200809L
#include "image_io.h"

#include <errno.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    /* Fast compression: captures are many and large; the files stay lossless. */
    png_set_compression_level(png, 1);
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
