/* A view's range.bin: its range image, reasons and colour, kept so that the model can be made
 * again without decoding (docs/scan-format.md); read back into a struct scan_ctx, or as
 * pictures for the report and the web page's thumbnails. */
#define _DEFAULT_SOURCE
#include "scan_dir.h"

#include "file_posix.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The file's header; then width * height reason bytes, then a range_point per valid pixel in
 * pixel order. Native byte order (little-endian on every board the scanner builds for). */
struct range_header {
    char magic[8]; /* "SCANRNG1" */
    uint32_t width, height, valid_count, colour_method;
    int32_t angle_mdeg;
    uint32_t reserved;
};
struct range_point {
    float xyz_mm[3], normal[3], confidence;
    uint8_t rgb[3], pad;
};
_Static_assert(sizeof(struct range_header) == 32 && sizeof(struct range_point) == 32,
               "range.bin's layout has no padding");
static const char range_magic[8] = {'S', 'C', 'A', 'N', 'R', 'N', 'G', '1'};
#define RANGE_CHUNK 2048u /* points a write or read moves at once */

int scan_dir_write_range(const struct hal_storage *st, const char *dir, uint32_t view,
                         const struct scan_view *v)
{
    struct range_point chunk[RANGE_CHUNK]; /* 64 KB */
    char path[SCAN_DIR_PATH_MAX];
    struct hal_file f;
    size_t n = (size_t)v->width * v->height, used = 0;
    uint32_t valid = 0;
    for (size_t i = 0; i < n; i++)
        valid += v->maps.reason[i] == SCAN_VALID;
    struct range_header h = {.width = v->width,
                             .height = v->height,
                             .valid_count = valid,
                             .colour_method = v->colour_method,
                             .angle_mdeg = v->angle_mdeg};
    memcpy(h.magic, range_magic, sizeof(h.magic));
    int rc = scan_dir_path(path, sizeof(path), dir, (int)view, SCAN_FILE_RANGE);
    if (rc == 0)
        rc = hal_storage_open(st, &f, path);
    if (rc != 0)
        return rc;
    rc = hal_storage_write(st, &f, &h, sizeof(h));
    if (rc == 0)
        rc = hal_storage_write(st, &f, v->maps.reason, n);
    for (size_t i = 0; i < n && rc == 0; i++) {
        if (v->maps.reason[i] != SCAN_VALID)
            continue;
        struct range_point *p = &chunk[used++];
        memcpy(p->xyz_mm, v->range.xyz_mm + 3 * i, sizeof(p->xyz_mm));
        memcpy(p->normal, v->range.normal + 3 * i, sizeof(p->normal));
        p->confidence = v->confidence[i];
        memcpy(p->rgb, v->rgb + 3 * i, 3);
        p->pad = 0;
        if (used == RANGE_CHUNK) {
            rc = hal_storage_write(st, &f, chunk, used * sizeof(chunk[0]));
            used = 0;
        }
    }
    if (rc == 0 && used > 0)
        rc = hal_storage_write(st, &f, chunk, used * sizeof(chunk[0]));
    if (rc == 0)
        return hal_storage_commit(st, &f);
    hal_storage_abort(st, &f);
    return rc;
}

/* range.bin of view @p view opened at its first reason byte, its header read and its magic
 * checked. @retval 0 @retval -errno (no such file) @retval -EINVAL (not a range image) */
static int range_open(const char *dir, uint32_t view, char *path, size_t path_len,
                      struct range_header *h, FILE **fp)
{
    int rc = scan_dir_path(path, path_len, dir, (int)view, SCAN_FILE_RANGE);
    *fp = rc == 0 ? file_open_regular(path, "rb") : NULL;
    if (*fp == NULL)
        return rc != 0 ? rc : -errno;
    if (fread(h, sizeof(*h), 1, *fp) == 1 && memcmp(h->magic, range_magic, sizeof(h->magic)) == 0)
        return 0;
    fclose(*fp);
    return -EINVAL;
}

/* The points of range.bin after the reasons @p reason (n pixels) already read: @p each is called
 * for every valid pixel in order, with its point (the caller has cleared the others: a call for
 * each of a view's million pixels cost more than the points' reading).
 * @retval 0 @retval -EINVAL cut short, or more points than valid pixels, or bytes after them */
static int read_range_points(FILE *fp, const uint8_t *reason, size_t n,
                             void (*each)(void *priv, size_t i, const struct range_point *p),
                             void *priv)
{
    struct range_point *chunk = malloc(RANGE_CHUNK * sizeof(*chunk)); /* callers in threads */
    size_t have = 0, next = 0;
    int rc = chunk != NULL ? 0 : -ENOMEM;
    const uint8_t *at = reason, *end = reason + n;
    _Static_assert(SCAN_VALID == 0, "valid pixels are found by memchr for 0");
    while (rc == 0 && at < end && (at = memchr(at, SCAN_VALID, (size_t)(end - at))) != NULL) {
        if (next == have) {
            /* read as bytes: fread of whole points drops a part of one at the end unsaid */
            size_t bytes = fread(chunk, 1, RANGE_CHUNK * sizeof(chunk[0]), fp);
            have = bytes / sizeof(chunk[0]);
            next = 0;
            if (have == 0 || bytes % sizeof(chunk[0]) != 0) {
                rc = -EINVAL;
                break;
            }
        }
        each(priv, (size_t)(at++ - reason), &chunk[next++]);
    }
    if (rc == 0 && (next != have || fgetc(fp) != EOF))
        rc = -EINVAL; /* nothing left over */
    free(chunk);
    return rc;
}

/* A point into the firmware's buffers (scan_dir_read_range). */
static void fill_point(void *priv, size_t i, const struct range_point *p)
{
    struct scan_view_fill *fill = priv;
    memcpy(fill->xyz_mm + 3 * i, p->xyz_mm, sizeof(p->xyz_mm));
    memcpy(fill->normal + 3 * i, p->normal, sizeof(p->normal));
    fill->confidence[i] = p->confidence;
    memcpy(fill->rgb + 3 * i, p->rgb, 3);
}

/* Nothing: the points counted only. */
static void skip_point(void *priv, size_t i, const struct range_point *p)
{
    (void)priv, (void)i, (void)p;
}

/* A point's colour into an RGB image (scan_dir_read_range_image). */
static void image_point(void *priv, size_t i, const struct range_point *p)
{
    memcpy((uint8_t *)priv + 3 * i, p->rgb, 3);
}

int scan_dir_read_range_image(const char *dir, uint32_t view, uint8_t *reason, uint8_t *rgb,
                              size_t capacity, uint32_t *width, uint32_t *height)
{
    char path[SCAN_DIR_PATH_MAX];
    struct range_header h;
    FILE *fp;
    int rc = range_open(dir, view, path, sizeof(path), &h, &fp);
    if (rc != 0)
        return rc;
    rc = -EINVAL;
    size_t n = (size_t)h.width * h.height;
    if (h.width == 0 || h.height == 0 || n > capacity || fread(reason, 1, n, fp) != n)
        goto out_close;
    for (size_t i = 0; i < n; i++)
        if (reason[i] >= SCAN_REASON_COUNT)
            goto out_close;
    if (rgb == NULL) { /* the points are not read: only that they are all there */
        rc = read_range_points(fp, reason, n, skip_point, NULL);
    } else {
        memset(rgb, 0, 3 * n); /* black where no point is */
        rc = read_range_points(fp, reason, n, image_point, rgb);
    }
    if (rc == 0) {
        *width = h.width;
        *height = h.height;
    }
out_close:
    fclose(fp);
    return rc;
}

int scan_dir_read_range(struct scan_ctx *s, const char *dir, uint32_t view, uint32_t width,
                        uint32_t height, struct scan_view *v, char *err, size_t err_len)
{
    char path[SCAN_DIR_PATH_MAX];
    struct range_header h;
    struct scan_view_fill fill;
    FILE *fp;
    int rc = range_open(dir, view, path, sizeof(path), &h, &fp);
    if (rc != 0) {
        snprintf(err, err_len, "%s: %s", path,
                 rc == -EINVAL ? "not a range image (range.bin)" : strerror(-rc));
        return rc;
    }
    size_t n = (size_t)width * height;
    rc = -EINVAL;
    const char *why = "of another frame size than this scan's";
    if (h.width != width || h.height != height || h.valid_count > n)
        goto out_close;
    why = "larger than the compiled frame limit";
    if (scan_restore_view(s, width, height, h.angle_mdeg, h.valid_count, h.colour_method, v,
                          &fill) != 0)
        goto out_close;
    why = "cut short or damaged";
    if (fread(fill.reason, 1, n, fp) != n)
        goto out_close;
    uint32_t valid = 0;
    for (size_t i = 0; i < n; i++) {
        if (fill.reason[i] >= SCAN_REASON_COUNT)
            goto out_close;
        valid += fill.reason[i] == SCAN_VALID;
    }
    memset(fill.rgb, 0, 3 * n); /* no colour and no trust where no point is */
    memset(fill.confidence, 0, n * sizeof(fill.confidence[0]));
    if (valid == h.valid_count && read_range_points(fp, fill.reason, n, fill_point, &fill) == 0)
        rc = 0;
out_close:
    if (rc != 0)
        snprintf(err, err_len, "%s: %s", path, why);
    fclose(fp);
    return rc;
}
