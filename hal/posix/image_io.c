/* PNG via libpng (into memory, then one atomic write), PGM/PPM raw or in zstd, and PFM. */
#define _POSIX_C_SOURCE 200809L
#include "image_io.h"

#include "file_posix.h"

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

int image_encode_png(const uint8_t *pixels, uint32_t width, uint32_t height, int channels,
                     uint8_t **png_data, size_t *png_len)
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
    if (!sink.failed) {
        *png_data = sink.data;
        *png_len = sink.len;
        sink.data = NULL;
        rc = 0;
    }
out_png:
    png_destroy_write_struct(&png, &info);
    free(sink.data);
    return rc;
}

int image_write_png(const struct hal_storage *st, const char *path, const uint8_t *pixels,
                    uint32_t width, uint32_t height, int channels)
{
    uint8_t *data = NULL;
    size_t len = 0;
    int rc = image_encode_png(pixels, width, height, channels, &data, &len);
    if (rc == 0)
        rc = hal_storage_write_file(st, path, data, len);
    free(data);
    return rc;
}

int image_read_png(const char *path, uint8_t *pixels, size_t capacity, uint32_t *width,
                   uint32_t *height, int channels, char *why, size_t why_len)
{
    png_image img;
    memset(&img, 0, sizeof(img));
    img.version = PNG_IMAGE_VERSION;
    FILE *fp = file_open_regular(path, "rb");
    if (fp == NULL) {
        int rc = -errno;
        snprintf(why, why_len, "%s", file_strerror(-rc));
        return rc;
    }
    if (!png_image_begin_read_from_stdio(&img, fp)) {
        snprintf(why, why_len, "%s", img.message);
        png_image_free(&img);
        fclose(fp);
        return -EINVAL;
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
    fclose(fp);
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

#define ZSTD_CHUNK (128u * 1024u) /* compressed bytes moved at a time, both ways */

/* The compressor a thread keeps for its frames (image_zstd_keep), and its output chunk. */
static _Thread_local struct zstd_out {
    ZSTD_CCtx *cctx;
    uint8_t *out;
} kept;

static void zstd_out_free(struct zstd_out *z)
{
    ZSTD_freeCCtx(z->cctx);
    free(z->out);
    z->cctx = NULL;
    z->out = NULL;
}

static int zstd_out_make(struct zstd_out *z)
{
    z->cctx = ZSTD_createCCtx();
    z->out = malloc(ZSTD_CHUNK);
    if (z->cctx != NULL && z->out != NULL)
        return 0;
    zstd_out_free(z);
    return -ENOMEM;
}

int image_zstd_keep(void)
{
    return kept.cctx != NULL ? 0 : zstd_out_make(&kept);
}

void image_zstd_release(void)
{
    zstd_out_free(&kept);
}

/* Header and pixels as one zstd frame, streamed to @p f a chunk at a time: neither the pixels
 * nor the compressed frame are copied whole. */
static int write_zstd(const struct hal_storage *st, struct hal_file *f, struct zstd_out *z,
                      const char *header, size_t header_len, const uint8_t *pixels, size_t n,
                      int level)
{
    ZSTD_CCtx_reset(z->cctx, ZSTD_reset_session_only);
    ZSTD_CCtx_setParameter(z->cctx, ZSTD_c_compressionLevel, level);
    /* the content size goes into the frame: readers know what they get before they get it */
    ZSTD_CCtx_setPledgedSrcSize(z->cctx, (unsigned long long)(header_len + n));
    ZSTD_inBuffer in[2] = {{header, header_len, 0}, {pixels, n, 0}};
    int rc = 0;
    for (int part = 0; part < 2 && rc == 0; part++) {
        ZSTD_EndDirective mode = part == 0 ? ZSTD_e_continue : ZSTD_e_end;
        size_t left;
        do {
            ZSTD_outBuffer o = {z->out, ZSTD_CHUNK, 0};
            left = ZSTD_compressStream2(z->cctx, &o, &in[part], mode);
            if (ZSTD_isError(left))
                return -EIO;
            if (o.pos > 0)
                rc = hal_storage_write(st, f, z->out, o.pos);
        } while (rc == 0 && (part == 0 ? in[0].pos < in[0].size : left != 0));
    }
    return rc;
}

int image_write_pnm(const struct hal_storage *st, const char *path, const uint8_t *pixels,
                    uint32_t width, uint32_t height, int channels, int zstd_level)
{
    char header[48];
    int hl = snprintf(header, sizeof(header), "P%c\n%u %u\n255\n", channels == 3 ? '6' : '5',
                      (unsigned)width, (unsigned)height);
    size_t n = (size_t)width * height * (size_t)channels;
    struct zstd_out temp = {NULL, NULL};
    struct hal_file f;
    int rc = hal_storage_open(st, &f, path);
    if (rc != 0)
        return rc;
    if (zstd_level == 0) { /* the bytes as they are: no copy */
        rc = hal_storage_write(st, &f, header, (size_t)hl);
        if (rc == 0)
            rc = hal_storage_write(st, &f, pixels, n);
    } else if (kept.cctx != NULL) {
        rc = write_zstd(st, &f, &kept, header, (size_t)hl, pixels, n, zstd_level);
    } else if ((rc = zstd_out_make(&temp)) == 0) { /* a thread that keeps none: one for now */
        rc = write_zstd(st, &f, &temp, header, (size_t)hl, pixels, n, zstd_level);
        zstd_out_free(&temp);
    }
    if (rc == 0)
        return hal_storage_commit(st, &f);
    hal_storage_abort(st, &f);
    return rc;
}

/* Width, height, channels and the offset of the pixels of a binary PGM/PPM of maxval 255 whose
 * first @p len bytes are @p d. */
static int parse_pnm(const uint8_t *d, size_t len, uint32_t *w, uint32_t *h, int *channels,
                     size_t *offset)
{
    unsigned vals[3];
    size_t i = 2;
    if (len < 2 || d[0] != 'P' || (d[1] != '5' && d[1] != '6'))
        return -EINVAL;
    for (int k = 0; k < 3; k++) {
        while (i < len &&
               (d[i] == ' ' || d[i] == '\t' || d[i] == '\r' || d[i] == '\n' || d[i] == '#')) {
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

/* A source of a file's bytes, decompressed when the file is a zstd frame. */
struct pnm_source {
    FILE *fp;
    ZSTD_DCtx *dctx; /* NULL: a raw file */
    uint8_t *in;
    ZSTD_inBuffer ib; /* starts empty: the first read fills it */
    int ended;        /* the zstd frame is complete */
};

/* Up to @p len bytes into @p out. @retval bytes read @retval -1 damaged (@p why says) */
static long source_read(struct pnm_source *s, uint8_t *out, size_t len, char *why, size_t why_len)
{
    if (s->dctx == NULL)
        return (long)fread(out, 1, len, s->fp);
    ZSTD_outBuffer o = {out, len, 0};
    while (o.pos < o.size && !s->ended) {
        /* what the input read so far gives (also the end of a frame whose data are all in) */
        size_t before_in = s->ib.pos, before_out = o.pos;
        size_t r = ZSTD_decompressStream(s->dctx, &o, &s->ib);
        if (ZSTD_isError(r)) {
            snprintf(why, why_len, "damaged zstd data (%s)", ZSTD_getErrorName(r));
            return -1;
        }
        s->ended = r == 0;
        if (s->ended || s->ib.pos != before_in || o.pos != before_out)
            continue;
        s->ib.src = s->in; /* no progress: more input */
        s->ib.size = fread(s->in, 1, ZSTD_CHUNK, s->fp);
        s->ib.pos = 0;
        if (s->ib.size == 0) {
            snprintf(why, why_len, "damaged zstd data (cut short)");
            return -1;
        }
    }
    return (long)o.pos;
}

int image_read_pnm(const char *path, uint8_t *pixels, size_t capacity, uint32_t *width,
                   uint32_t *height, int channels, char *why, size_t why_len)
{
    struct pnm_source src = {.fp = file_open_regular(path, "rb")};
    uint8_t head[64], magic[4];
    if (src.fp == NULL) {
        int rc = -errno;
        snprintf(why, why_len, "%s", file_strerror(-rc));
        return rc;
    }
    int rc = -EINVAL;
    size_t got = fread(magic, 1, sizeof(magic), src.fp);
    rewind(src.fp);
    uint32_t zstd_magic = ZSTD_MAGICNUMBER; /* a zstd frame begins with it, little-endian */
    uint8_t zm[4] = {(uint8_t)zstd_magic, (uint8_t)(zstd_magic >> 8), (uint8_t)(zstd_magic >> 16),
                     (uint8_t)(zstd_magic >> 24)};
    if (got == sizeof(magic) && memcmp(magic, zm, sizeof(zm)) == 0) {
        src.dctx = ZSTD_createDCtx();
        src.in = malloc(ZSTD_CHUNK);
        if (src.dctx == NULL || src.in == NULL) {
            snprintf(why, why_len, "%s", strerror(ENOMEM));
            rc = -ENOMEM;
            goto out_free;
        }
    }
    /* the header from the first bytes, then the pixels straight into the caller's buffer */
    long have = source_read(&src, head, sizeof(head), why, why_len);
    uint32_t w = 0, h = 0;
    int stored = 0;
    size_t offset = 0;
    if (have < 0)
        goto out_free;
    if (parse_pnm(head, (size_t)have, &w, &h, &stored, &offset) != 0) {
        snprintf(why, why_len, "not an 8-bit binary PGM or PPM");
        goto out_free;
    }
    size_t n = (size_t)w * h * (size_t)stored;
    if (stored == 3 && channels == 1) {
        snprintf(why, why_len, "an RGB frame where a grey one belongs");
        goto out_free;
    }
    if ((size_t)w * h * (size_t)channels > capacity) {
        snprintf(why, why_len, "%ux%u, larger than the compiled frame limit", (unsigned)w,
                 (unsigned)h);
        goto out_free;
    }
    size_t first = (size_t)have - offset < n ? (size_t)have - offset : n;
    memcpy(pixels, head + offset, first);
    if (src.dctx == NULL && fseek(src.fp, (long)(offset + first), SEEK_SET) != 0)
        goto out_free;
    long rest = first < n ? source_read(&src, pixels + first, n - first, why, why_len) : 0;
    if (rest < 0)
        goto out_free;
    uint8_t extra;
    if (first + (size_t)rest < n) {
        snprintf(why, why_len, "truncated: %zu bytes of pixels for %ux%u", first + (size_t)rest,
                 (unsigned)w, (unsigned)h);
        goto out_free;
    }
    /* a zstd frame must end with the image (its checksum, if any, read) */
    long more = (size_t)have - offset > n ? 1 : 0;
    if (more == 0 && src.dctx != NULL && !src.ended)
        more = source_read(&src, &extra, 1, why, why_len);
    if (more < 0)
        goto out_free;
    if (more == 0 && src.dctx != NULL &&
        (src.ib.pos < src.ib.size || fgetc(src.fp) != EOF)) { /* more after the frame */
        snprintf(why, why_len, "damaged zstd data (bytes after its frame)");
        goto out_free;
    }
    if (more > 0) {
        snprintf(why, why_len, "more bytes than a %ux%u image", (unsigned)w, (unsigned)h);
        goto out_free;
    }
    if (stored == 1 && channels == 3) /* grey to RGB, from the end so nothing is overwritten */
        for (size_t i = (size_t)w * h; i-- > 0;)
            memset(pixels + 3 * i, pixels[i], 3);
    *width = w;
    *height = h;
    rc = 0;
out_free:
    free(src.in);
    ZSTD_freeDCtx(src.dctx);
    fclose(src.fp);
    return rc;
}
