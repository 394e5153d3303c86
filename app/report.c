/* report.html: a scan directory described in one self-contained page (pictures inline as PNG
 * data URIs, so it opens from the file system, a USB stick or the web page alike). A setup
 * tool's job, run after the scan: it allocates as it needs, outside the firmware's memory. */
#define _POSIX_C_SOURCE 200809L
#include "report.h"
#include "file_posix.h"

#include "decode.h"
#include "image_io.h"
#include "scan_dir.h"
#include "srgb.h"

#include <errno.h>
#include <ini.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* ---- the page, a text that grows ---- */

struct text {
    char *s;
    size_t len, cap;
    int failed;
};

static void text_reserve(struct text *t, size_t more)
{
    if (t->failed || t->len + more + 1 <= t->cap)
        return;
    size_t cap = (t->len + more + 1) * 2;
    char *s = realloc(t->s, cap);
    if (s == NULL) {
        t->failed = 1;
        return;
    }
    t->s = s;
    t->cap = cap;
}

__attribute__((format(printf, 2, 3))) static void text_printf(struct text *t, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    text_reserve(t, (size_t)(n > 0 ? n : 0));
    if (t->failed || n <= 0)
        return;
    va_start(ap, fmt);
    vsnprintf(t->s + t->len, t->cap - t->len, fmt, ap);
    va_end(ap);
    t->len += (size_t)n;
}

/* @p s with &, <, >, " escaped (names come from the file system and the config). */
static void text_html(struct text *t, const char *s)
{
    for (; *s != '\0'; s++) {
        const char *e = *s == '&'   ? "&amp;"
                        : *s == '<' ? "&lt;"
                        : *s == '>' ? "&gt;"
                        : *s == '"' ? "&quot;"
                                    : NULL;
        if (e != NULL)
            text_printf(t, "%s", e);
        else
            text_printf(t, "%c", *s);
    }
}

/* RFC 4648 base64, for the data URIs (a dozen lines: no Debian C library is lighter than it). */
static void text_base64(struct text *t, const uint8_t *d, size_t n)
{
    static const char abc[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    text_reserve(t, (n + 2) / 3 * 4);
    if (t->failed)
        return;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)d[i] << 16 | (i + 1 < n ? (uint32_t)d[i + 1] << 8 : 0) |
                     (i + 2 < n ? d[i + 2] : 0);
        char *o = t->s + t->len;
        o[0] = abc[v >> 18 & 63];
        o[1] = abc[v >> 12 & 63];
        o[2] = i + 1 < n ? abc[v >> 6 & 63] : '=';
        o[3] = i + 2 < n ? abc[v & 63] : '=';
        t->len += 4;
    }
    t->s[t->len] = '\0';
}

/* <img> of an 8-bit image, inline. */
static void text_img(struct text *t, const uint8_t *pixels, uint32_t w, uint32_t h, int channels,
                     const char *alt)
{
    uint8_t *png = NULL;
    size_t len = 0;
    if (image_encode_png(pixels, w, h, channels, &png, &len) != 0) {
        text_printf(t, "<span class=missing>(no picture: out of memory)</span>");
        return;
    }
    text_printf(t, "<img width=%u height=%u alt=\"", (unsigned)w, (unsigned)h);
    text_html(t, alt);
    text_printf(t, "\" src=\"data:image/png;base64,");
    text_base64(t, png, len);
    text_printf(t, "\">");
    free(png);
}

/* ---- the scan's small ini files (summary.ini, registration.ini, config.ini) ---- */

#define KV_MAX 160u
struct kvs {
    struct kv {
        char section[32], key[48], value[256];
    } e[KV_MAX];
    unsigned n;
};

static int kv_add(void *user, const char *section, const char *key, const char *value)
{
    struct kvs *k = user;
    if (k->n < KV_MAX) {
        struct kv *e = &k->e[k->n++];
        snprintf(e->section, sizeof(e->section), "%s", section);
        snprintf(e->key, sizeof(e->key), "%s", key);
        snprintf(e->value, sizeof(e->value), "%s", value);
    }
    return 1;
}

/* @retval 0 read (a damaged line is skipped: the report shows what it can) @retval -ENOENT */
static int kv_read(struct kvs *k, const char *dir, int view, const char *name)
{
    char path[SCAN_DIR_PATH_MAX];
    k->n = 0;
    if (scan_dir_path(path, sizeof(path), dir, view, name) != 0)
        return -ENAMETOOLONG;
    FILE *f = file_open_regular(path, "r"); /* a pipe planted there must not hang the report */
    if (f == NULL)
        return -errno;
    ini_parse_file(f, kv_add, k);
    fclose(f);
    return 0;
}

static const char *kv_get(const struct kvs *k, const char *section, const char *key)
{
    for (unsigned i = 0; i < k->n; i++)
        if (strcmp(k->e[i].section, section) == 0 && strcmp(k->e[i].key, key) == 0)
            return k->e[i].value;
    return NULL;
}

static double kv_num(const struct kvs *k, const char *section, const char *key, double dflt)
{
    const char *v = kv_get(k, section, key);
    return v != NULL && *v != '\0' ? atof(v) : dflt;
}

/* ---- thumbnails ---- */

const char *report_reason_colour(unsigned reason)
{
    static const char *const colour[SCAN_REASON_COUNT] = {
        "#3fa34d", /* valid */
        "#2b2b2b", /* shadow */
        "#2f5fb3", /* dark */
        "#e3a21a", /* low contrast */
        "#d7263d", /* saturated */
        "#9b4dca", /* inconsistent */
    };
    return reason < SCAN_REASON_COUNT ? colour[reason] : "#ffffff";
}

static void reason_rgb(unsigned reason, uint8_t rgb[3])
{
    unsigned v = (unsigned)strtoul(report_reason_colour(reason) + 1, NULL, 16);
    rgb[0] = (uint8_t)(v >> 16);
    rgb[1] = (uint8_t)(v >> 8);
    rgb[2] = (uint8_t)v;
}

/* The view's colour frame: the one view.ini names "the view's colour". @retval -ENOENT none */
static int colour_frame_of(const char *dir, uint32_t view, uint32_t *frame)
{
    struct scan_dir_view *v = malloc(sizeof(*v)); /* large; the web server's threads ask too */
    char err[256];
    int rc = -ENOENT;
    if (v != NULL && scan_dir_read_view(dir, view, v, err, sizeof(err)) == 0)
        for (uint32_t f = 0; rc != 0 && f < v->frame_count; f++)
            if (strstr(v->frame_name[f], "the view's colour") != NULL) {
                *frame = f;
                rc = 0;
            }
    free(v);
    return rc;
}

/* What a view's thumbnails are made of: its range image's reasons and colours (linear x 255),
 * and its camera's colour frame (NULL where not kept). Read once for all three. */
struct view_images {
    uint8_t *reason, *rgb, *frame;
    uint32_t w, h;
};

static void view_images_free(struct view_images *vi)
{
    free(vi->frame);
    free(vi->rgb);
    free(vi->reason);
    *vi = (struct view_images){0};
}

/* @p want_frame: the camera's frame too. @retval 0 @retval -ENOENT no range.bin (yet)
 * @retval -EINVAL damaged @retval -ENOMEM */
static int view_images_read(const char *dir, uint32_t view, int want_frame, struct view_images *vi)
{
    *vi = (struct view_images){0};
    vi->reason = malloc(HAL_MAX_PIXELS);
    vi->rgb = malloc(3u * HAL_MAX_PIXELS);
    int rc = vi->reason != NULL && vi->rgb != NULL ? 0 : -ENOMEM;
    if (rc == 0)
        rc = scan_dir_read_range_image(dir, view, vi->reason, vi->rgb, HAL_MAX_PIXELS, &vi->w,
                                       &vi->h);
    uint32_t frame;
    char err[256];
    if (rc == 0 && want_frame && colour_frame_of(dir, view, &frame) == 0 &&
        (vi->frame = malloc(3u * vi->w * vi->h)) != NULL &&
        scan_dir_read_frame(dir, view, frame, vi->frame, 3u * vi->w * vi->h, vi->w, vi->h, 3, err,
                            sizeof(err)) != 0) {
        free(vi->frame); /* not kept (keep_frames), or unreadable: that picture is missing */
        vi->frame = NULL;
    }
    if (rc != 0)
        view_images_free(vi);
    return rc;
}

/* Thumbnail @p kind of @p vi, box-filtered to @p tw x @p th (RGB, @p out of REPORT_THUMB_WIDTH
 * squared x 3 bytes at least): colour as a mean (the compensated colour encoded as a screen
 * shows it, sRGB, before averaging), reasons as the most common in the box.
 * @retval 0 @retval -ENOENT the camera's frame is not kept */
/* The box of source pixels [x0, x1) x [y0, y1) of @p src (@p w wide) into thumbnail pixel @p o:
 * the most common reason, or the mean of each channel (sRGB-encoded first when @p encode). The
 * kind is decided once a box, not at each of the million source pixels a view has. */
static void thumb_box(const uint8_t *src, uint32_t w, uint32_t x0, uint32_t x1, uint32_t y0,
                      uint32_t y1, int reasons, int encode, uint8_t *o)
{
    uint32_t sum[3] = {0, 0, 0}, count[SCAN_REASON_COUNT] = {0}, n = (x1 - x0) * (y1 - y0);
    for (uint32_t y = y0; y < y1; y++) {
        const uint8_t *row = src + (size_t)y * w * (reasons ? 1 : 3);
        if (reasons)
            for (uint32_t x = x0; x < x1; x++)
                count[row[x] < SCAN_REASON_COUNT ? row[x] : 0]++;
        else if (encode)
            for (uint32_t x = x0; x < x1; x++)
                for (int c = 0; c < 3; c++)
                    sum[c] += srgb_encode(row[3 * x + c]);
        else
            for (uint32_t x = x0; x < x1; x++)
                for (int c = 0; c < 3; c++)
                    sum[c] += row[3 * x + c];
    }
    if (reasons) {
        unsigned best = 0;
        for (unsigned r = 1; r < SCAN_REASON_COUNT; r++)
            best = count[r] > count[best] ? r : best;
        reason_rgb(best, o);
        return;
    }
    for (int c = 0; c < 3; c++)
        o[c] = (uint8_t)(n ? sum[c] / n : 0);
}

static int thumb_of(const struct view_images *vi, enum report_thumb kind, uint8_t *out,
                    uint32_t *tw, uint32_t *th)
{
    const uint8_t *src = kind == REPORT_THUMB_RAW       ? vi->frame
                         : kind == REPORT_THUMB_REASONS ? vi->reason
                                                        : vi->rgb;
    uint32_t w = vi->w, h = vi->h;
    if (src == NULL)
        return -ENOENT;
    *tw = REPORT_THUMB_WIDTH;
    *th = (uint32_t)((uint64_t)h * REPORT_THUMB_WIDTH / w);
    if (*th > REPORT_THUMB_WIDTH)
        *th = REPORT_THUMB_WIDTH;
    for (uint32_t ty = 0; ty < *th; ty++)
        for (uint32_t tx = 0; tx < *tw; tx++)
            thumb_box(src, w, tx * w / *tw, (tx + 1) * w / *tw, ty * h / *th, (ty + 1) * h / *th,
                      kind == REPORT_THUMB_REASONS, kind == REPORT_THUMB_INTRINSIC,
                      out + 3 * ((size_t)ty * *tw + tx));
    return 0;
}

int report_thumb_png(const char *dir, uint32_t view, enum report_thumb kind, uint8_t **png,
                     size_t *png_len)
{
    uint8_t *pixels =
        malloc(3u * REPORT_THUMB_WIDTH * REPORT_THUMB_WIDTH); /* reentrant: the
                                                                 web server's threads */
    struct view_images vi;
    uint32_t tw, th;
    int rc = pixels != NULL ? view_images_read(dir, view, kind == REPORT_THUMB_RAW, &vi) : -ENOMEM;
    if (rc == 0)
        rc = thumb_of(&vi, kind, pixels, &tw, &th);
    if (rc == 0)
        rc = image_encode_png(pixels, tw, th, 3, png, png_len);
    if (pixels != NULL)
        view_images_free(&vi);
    free(pixels);
    return rc;
}

/* ---- the model seen from around: mesh.ply drawn flat-shaded into a z-buffer ---- */

#define MODEL_PICTURE 220 /* pixels, square */

struct model {
    float *xyz;   /* 3 per vertex, object frame, mm (z up: the turntable's axis) */
    uint8_t *rgb; /* sRGB */
    uint32_t vertices, triangles;
    uint32_t *tri;
};

static size_t ply_type_size(const char *type)
{
    if (strcmp(type, "float") == 0 || strcmp(type, "float32") == 0 || strcmp(type, "int") == 0 ||
        strcmp(type, "uint") == 0 || strcmp(type, "int32") == 0 || strcmp(type, "uint32") == 0)
        return 4;
    if (strcmp(type, "uchar") == 0 || strcmp(type, "uint8") == 0 || strcmp(type, "char") == 0)
        return 1;
    if (strcmp(type, "double") == 0)
        return 8;
    return strcmp(type, "short") == 0 || strcmp(type, "ushort") == 0 ? 2 : 0;
}

/* The scan's own mesh.ply (binary little-endian, float xyz, uchar rgb, triangles as
 * "list uchar uint"): as scan_dir's writer makes it; anything else is refused. */
static int model_read(const char *dir, struct model *m)
{
    char path[SCAN_DIR_PATH_MAX], line[256];
    long offset[6] = {-1, -1, -1, -1, -1, -1}; /* x y z red green blue */
    static const char *const names[6] = {"x", "y", "z", "red", "green", "blue"};
    size_t stride = 0;
    int in_vertex = 0, rc = -EINVAL;
    *m = (struct model){0};
    if (scan_dir_path(path, sizeof(path), dir, -1, SCAN_FILE_MESH_PLY) != 0)
        return -ENAMETOOLONG;
    FILE *fp = file_open_regular(path, "rb");
    if (fp == NULL)
        return -errno;
    while (fgets(line, sizeof(line), fp) != NULL && strcmp(line, "end_header\n") != 0) {
        char type[32], name[64];
        unsigned long count;
        if (sscanf(line, "element vertex %lu", &count) == 1) {
            m->vertices = (uint32_t)count;
            in_vertex = 1;
        } else if (sscanf(line, "element face %lu", &count) == 1) {
            m->triangles = (uint32_t)count;
            in_vertex = 0;
        } else if (in_vertex && sscanf(line, "property %31s %63s", type, name) == 2) {
            for (int k = 0; k < 6; k++)
                if (strcmp(name, names[k]) == 0)
                    offset[k] = (long)stride;
            stride += ply_type_size(type);
        }
    }
    for (int k = 0; k < 6; k++)
        if (offset[k] < 0)
            goto out_close;
    m->xyz = malloc(sizeof(float) * 3u * m->vertices);
    m->rgb = malloc(3u * (size_t)m->vertices);
    m->tri = malloc(sizeof(uint32_t) * 3u * m->triangles);
    uint8_t rec[256];
    if (m->xyz == NULL || m->rgb == NULL || m->tri == NULL || stride > sizeof(rec)) {
        rc = -ENOMEM;
        goto out_close;
    }
    for (uint32_t v = 0; v < m->vertices; v++) {
        if (fread(rec, stride, 1, fp) != 1)
            goto out_close;
        for (int k = 0; k < 3; k++) {
            memcpy(&m->xyz[3 * v + (uint32_t)k], rec + offset[k], sizeof(float));
            m->rgb[3 * v + (uint32_t)k] = rec[offset[3 + k]];
        }
    }
    for (uint32_t t = 0; t < m->triangles; t++) {
        uint8_t n;
        if (fread(&n, 1, 1, fp) != 1 || n != 3 || fread(&m->tri[3 * t], 4, 3, fp) != 3)
            goto out_close;
        for (int k = 0; k < 3; k++)
            if (m->tri[3 * t + (uint32_t)k] >= m->vertices)
                goto out_close;
    }
    rc = 0;
out_close:
    fclose(fp);
    return rc;
}

static void model_free(struct model *m)
{
    free(m->xyz);
    free(m->rgb);
    free(m->tri);
}

/* Orthographic, looking along -@p dir with @p right and @p up on screen; every picture at the
 * same scale about @p centre, so that the sides compare. */
static void model_draw(const struct model *m, const double dir[3], const double right[3],
                       const double up[3], const double centre[3], double px_per_mm, uint8_t *img,
                       float *depth)
{
    const int size = MODEL_PICTURE;
    for (int i = 0; i < size * size; i++) {
        depth[i] = -INFINITY;
        img[3 * i] = img[3 * i + 1] = img[3 * i + 2] = 236; /* a gap shows the page's grey */
    }
    for (uint32_t t = 0; t < m->triangles; t++) {
        double sx[3], sy[3], sz[3], p[3][3];
        for (int k = 0; k < 3; k++) {
            const float *v = &m->xyz[3 * m->tri[3 * t + (uint32_t)k]];
            for (int c = 0; c < 3; c++)
                p[k][c] = v[c] - centre[c];
            sx[k] = size / 2.0 +
                    px_per_mm * (p[k][0] * right[0] + p[k][1] * right[1] + p[k][2] * right[2]);
            sy[k] = size / 2.0 - px_per_mm * (p[k][0] * up[0] + p[k][1] * up[1] + p[k][2] * up[2]);
            sz[k] = p[k][0] * dir[0] + p[k][1] * dir[1] + p[k][2] * dir[2];
        }
        /* Lambert with the light at the eye: |n . dir| of the face's normal */
        double e1[3], e2[3], n[3];
        for (int c = 0; c < 3; c++) {
            e1[c] = p[1][c] - p[0][c];
            e2[c] = p[2][c] - p[0][c];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double shade =
            nl > 0 ? 0.3 + 0.7 * fabs(n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2]) / nl : 0.3;
        double area = (sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0]);
        if (fabs(area) < 1e-12)
            continue;
        int x0 = (int)floor(fmin(sx[0], fmin(sx[1], sx[2]))),
            x1 = (int)ceil(fmax(sx[0], fmax(sx[1], sx[2])));
        int y0 = (int)floor(fmin(sy[0], fmin(sy[1], sy[2]))),
            y1 = (int)ceil(fmax(sy[0], fmax(sy[1], sy[2])));
        x0 = x0 < 0 ? 0 : x0;
        y0 = y0 < 0 ? 0 : y0;
        x1 = x1 >= size ? size - 1 : x1;
        y1 = y1 >= size ? size - 1 : y1;
        for (int y = y0; y <= y1; y++)
            for (int x = x0; x <= x1; x++) {
                double qx = x + 0.5, qy = y + 0.5, b[3];
                /* barycentric weights from the edge functions */
                b[0] = ((sx[1] - qx) * (sy[2] - qy) - (sx[2] - qx) * (sy[1] - qy)) / area;
                b[1] = ((sx[2] - qx) * (sy[0] - qy) - (sx[0] - qx) * (sy[2] - qy)) / area;
                b[2] = 1.0 - b[0] - b[1];
                if (b[0] < 0 || b[1] < 0 || b[2] < 0)
                    continue;
                float z = (float)(b[0] * sz[0] + b[1] * sz[1] + b[2] * sz[2]);
                int i = y * size + x;
                if (z <= depth[i])
                    continue;
                depth[i] = z;
                for (int c = 0; c < 3; c++) {
                    double col = 0;
                    for (int k = 0; k < 3; k++)
                        col += b[k] * m->rgb[3 * m->tri[3 * t + (uint32_t)k] + (uint32_t)c];
                    img[3 * i + c] = (uint8_t)fmin(255.0, col * shade + 0.5);
                }
            }
    }
}

/* The model from the front, the sides, the back and above, at one scale. */
static void model_section(struct text *t, const char *dir)
{
    struct model m;
    int rc = model_read(dir, &m);
    text_printf(t, "<h2>The model from around</h2>\n");
    if (rc != 0 || m.vertices == 0) {
        text_printf(t, "<p class=missing>No model (mesh.ply %s).</p>\n",
                    rc == -ENOENT ? "was not made: the scan did not finish" : "cannot be read");
        model_free(&m);
        return;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t v = 0; v < m.vertices; v++)
        for (int c = 0; c < 3; c++) {
            lo[c] = fmin(lo[c], m.xyz[3 * v + (uint32_t)c]);
            hi[c] = fmax(hi[c], m.xyz[3 * v + (uint32_t)c]);
        }
    double centre[3], radius = 0;
    for (int c = 0; c < 3; c++) {
        centre[c] = (lo[c] + hi[c]) / 2;
        radius += (hi[c] - lo[c]) * (hi[c] - lo[c]) / 4;
    }
    double px_per_mm = 0.46 * MODEL_PICTURE / fmax(sqrt(radius), 1e-3);
    uint8_t *img = malloc(3u * MODEL_PICTURE * MODEL_PICTURE);
    float *depth = malloc(sizeof(float) * MODEL_PICTURE * MODEL_PICTURE);
    text_printf(t,
                "<p>%u vertices, %u triangles, %.1f &times; %.1f &times; %.1f mm. "
                "Where the page's grey shows through, no view saw the surface.</p>\n<div "
                "class=row>",
                (unsigned)m.vertices, (unsigned)m.triangles, hi[0] - lo[0], hi[1] - lo[1],
                hi[2] - lo[2]);
    static const char *const side[] = {"front", "right", "back", "left", "above"};
    for (int k = 0; k < 5 && img != NULL && depth != NULL; k++) {
        double a = k * M_PI / 2, up[3] = {0, 0, 1};
        double dir[3] = {-sin(a), -cos(a), 0}, right[3] = {cos(a), -sin(a), 0};
        if (k == 4) { /* from above, the front at the bottom */
            dir[0] = dir[1] = 0;
            dir[2] = 1;
            up[0] = up[2] = 0;
            up[1] = 1;
            right[0] = 1;
            right[1] = right[2] = 0;
        }
        model_draw(&m, dir, right, up, centre, px_per_mm, img, depth);
        text_printf(t, "<figure>");
        text_img(t, img, MODEL_PICTURE, MODEL_PICTURE, 3, side[k]);
        text_printf(t, "<figcaption>%s</figcaption></figure>", side[k]);
    }
    text_printf(t, "</div>\n");
    free(depth);
    free(img);
    model_free(&m);
}

/* ---- the sections ---- */

static void timings_section(struct text *t, const char *dir)
{
    struct kvs k;
    text_printf(t, "<h2>Timings</h2>\n");
    if (kv_read(&k, dir, -1, SCAN_FILE_SUMMARY) != 0) {
        text_printf(t, "<p class=missing>No summary.ini: the scan did not finish.</p>\n");
        return;
    }
    text_printf(t, "<table><tr><th>stage</th><th>seconds</th><th>ended at (s)</th></tr>\n");
    double before = 0;
    for (unsigned i = 0; i < k.n; i++) {
        if (strcmp(k.e[i].section, "stages") != 0)
            continue;
        double at = atof(k.e[i].value);
        text_printf(t, "<tr><td>");
        text_html(t, k.e[i].key);
        text_printf(t, "</td><td>%.1f</td><td>%.1f</td></tr>\n", at - before, at);
        before = at;
    }
    text_printf(t,
                "<tr><th>whole %s</th><th>%.1f</th><th></th></tr></table>\n<p>Peak memory "
                "%.1f MB; %.2f s of the scanner's CPU.</p>\n",
                kv_get(&k, "summary", "command") ? kv_get(&k, "summary", "command") : "job",
                kv_num(&k, "summary", "elapsed_s", 0), kv_num(&k, "summary", "peak_memory_mb", 0),
                kv_num(&k, "summary", "cpu_s", 0));
}

/* The report's list of warnings, begun at the first. */
struct warning_list {
    struct text *t;
    unsigned shown;
};

static void warning_item(void *priv, const char *line)
{
    struct warning_list *w = priv;
    if (line[0] == '\0')
        return;
    if (w->shown++ == 0)
        text_printf(w->t, "<h2>Warnings</h2>\n<ul class=warnings>\n");
    text_printf(w->t, "<li>");
    text_html(w->t, line);
    text_printf(w->t, "</li>\n");
}

/* What the model lacks (warnings.txt, as the scan said it), first: a model cut by the volume or
 * the image must not pass for the object. Nothing when there is none. */
static void warnings_section(struct text *t, const char *dir)
{
    struct warning_list w = {t, 0};
    scan_dir_each_warning(dir, 16, 1024, warning_item, &w);
    if (w.shown > 0)
        text_printf(t, "</ul>\n");
}

static void registration_section(struct text *t, const char *dir)
{
    struct kvs k;
    text_printf(t, "<h2>Registration</h2>\n");
    if (kv_read(&k, dir, 0, SCAN_FILE_REGISTRATION) != 0) {
        text_printf(t, "<p class=missing>Not registered yet.</p>\n");
        return;
    }
    const char *refused = kv_get(&k, "registration", "refused");
    text_printf(t,
                "<p>%s Residual %.3f mm over every overlap (%.3f mm before), loop closure "
                "%.3f mm, worst view %d (%.3f mm); the turntable's axis moved %.2f mm and tilted "
                "%.2f&deg;.</p>\n",
                kv_num(&k, "registration", "accepted", 0) > 0 ? "The views were placed by ICP."
                                                              : "The turntable's angles were kept.",
                kv_num(&k, "registration", "rms_mm", 0),
                kv_num(&k, "registration", "score_before_mm", 0),
                kv_num(&k, "registration", "loop_closure_rms_mm", 0),
                (int)kv_num(&k, "registration", "worst_view", 0),
                kv_num(&k, "registration", "worst_rms_mm", 0),
                kv_num(&k, "registration", "axis_shift_mm", 0),
                kv_num(&k, "registration", "axis_tilt_deg", 0));
    if (refused != NULL && *refused != '\0') {
        text_printf(t, "<p>Refused: ");
        text_html(t, refused);
        text_printf(t, "</p>\n");
    }
}

/* A cell with thumbnail @p kind of @p vi (NULL: the view has no range image). */
static void thumb_cell(struct text *t, const struct view_images *vi, enum report_thumb kind,
                       const char *alt)
{
    uint8_t pixels[3u * REPORT_THUMB_WIDTH * REPORT_THUMB_WIDTH];
    uint32_t tw, th;
    text_printf(t, "<td>");
    if (vi != NULL && thumb_of(vi, kind, pixels, &tw, &th) == 0)
        text_img(t, pixels, tw, th, 3, alt);
    else
        text_printf(t, "<span class=missing>not kept</span>");
    text_printf(t, "</td>");
}

static void views_section(struct text *t, const char *dir, uint32_t views, const char *method)
{
    struct scan_dir_view v;
    struct kvs reg;
    char err[256];
    text_printf(t, "<h2>Views</h2>\n<p class=legend>Reason map: ");
    for (unsigned r = 0; r < SCAN_REASON_COUNT; r++)
        text_printf(t, "<span><i style=\"background:%s\"></i>%s</span> ", report_reason_colour(r),
                    scan_reason_name(r));
    text_printf(t, "</p>\n<table><tr><th>view</th><th>angle (&deg;)<br>table &rarr; "
                   "registered</th><th>valid points</th><th>residual (mm)</th><th>camera "
                   "(before compensation)</th><th>colour (after: ");
    text_html(t, method);
    text_printf(t, ")</th><th>reason map</th></tr>\n");
    for (uint32_t i = 0; i < views; i++) {
        if (scan_dir_read_view(dir, i, &v, err, sizeof(err)) != 0) {
            text_printf(t, "<tr><td>%u</td><td colspan=6 class=missing>not taken</td></tr>\n",
                        (unsigned)i);
            continue;
        }
        text_printf(t, "<tr><td>%u</td><td>%.3f", (unsigned)i, v.angle_mdeg / 1000.0);
        if (kv_read(&reg, dir, (int)i, SCAN_FILE_REGISTRATION) == 0)
            text_printf(t, " &rarr; %.3f<br>(%+.3f)</td><td>%u</td><td>%.3f</td>",
                        kv_num(&reg, "view", "angle_deg", 0),
                        kv_num(&reg, "view", "correction_deg", 0), (unsigned)v.valid_points,
                        kv_num(&reg, "view", "view_rms_mm", 0));
        else
            text_printf(t, "</td><td>%u</td><td></td>", (unsigned)v.valid_points);
        struct view_images vi;
        int have = view_images_read(dir, i, 1, &vi) == 0;
        thumb_cell(t, have ? &vi : NULL, REPORT_THUMB_RAW, "camera");
        thumb_cell(t, have ? &vi : NULL, REPORT_THUMB_INTRINSIC, "colour");
        thumb_cell(t, have ? &vi : NULL, REPORT_THUMB_REASONS, "reason map");
        view_images_free(&vi);
        text_printf(t, "</tr>\n");
    }
    text_printf(t, "</table>\n");
}

static const char report_style[] =
    "body{font:14px/1.4 system-ui,sans-serif;margin:1.5em;color:#222;background:#fafafa}"
    "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:4px 8px;"
    "vertical-align:middle;text-align:left}figure{display:inline-block;margin:0 8px 8px 0}"
    "figcaption{text-align:center;color:#555}.missing{color:#999}.legend span{margin-right:1em}"
    ".legend i{display:inline-block;width:12px;height:12px;margin-right:4px;"
    "vertical-align:middle;border:1px solid #888}img{display:block}.warnings{color:#92400e}";

/* The name a scan directory goes by: its last path component. */
static const char *dir_name(const char *dir)
{
    const char *slash = strrchr(dir, '/');
    while (slash != NULL && slash[1] == '\0' && slash > dir) { /* "scans/x/" */
        const char *p = slash - 1;
        while (p > dir && *p != '/')
            p--;
        return *p == '/' ? p + 1 : p;
    }
    return slash != NULL ? slash + 1 : dir;
}

int report_write(const struct hal_storage *st, const char *dir, char *err, size_t err_len)
{
    struct kvs cfg;
    struct text t = {0};
    char path[SCAN_DIR_PATH_MAX];
    int rc = kv_read(&cfg, dir, -1, SCAN_FILE_CONFIG);
    if (rc != 0) {
        snprintf(err, err_len, "%s/config.ini: %s (not a scan directory?)", dir, strerror(-rc));
        return rc;
    }
    uint32_t views, done = 0;
    scan_dir_view_count(dir, &views); /* its config.ini, read just above */
    for (uint32_t v = 0; v < views; v++)
        done += (uint32_t)scan_dir_view_complete(dir, v);
    const char *method = kv_get(&cfg, "colour", "method");
    method = method != NULL ? method : "none";
    text_printf(&t, "<!doctype html>\n<html lang=en><head><meta charset=utf-8><title>Scan ");
    text_html(&t, dir_name(dir));
    text_printf(&t, "</title><style>%s</style></head><body>\n<h1>Scan ", report_style);
    text_html(&t, dir_name(dir));
    text_printf(&t, "</h1>\n<p class=state>%u of %u views taken. Files: ", (unsigned)done,
                (unsigned)views);
    static const char *const files[] = {
        SCAN_FILE_MESH_PLY, SCAN_FILE_MESH_OBJ, SCAN_FILE_MESH_MTL, SCAN_FILE_TEXTURE,
        SCAN_FILE_MESH_STL, SCAN_FILE_MESH_GLB, SCAN_FILE_CONFIG,   SCAN_FILE_CALIBRATION};
    struct stat sb;
    for (size_t f = 0; f < sizeof(files) / sizeof(files[0]); f++)
        if (scan_dir_path(path, sizeof(path), dir, -1, files[f]) == 0 && stat(path, &sb) == 0)
            text_printf(&t, "<a href=\"%s\">%s</a> (%.1f MB) ", files[f], files[f],
                        sb.st_size / 1e6);
    text_printf(&t, "</p>\n");
    warnings_section(&t, dir);
    model_section(&t, dir);
    timings_section(&t, dir);
    registration_section(&t, dir);
    views_section(&t, dir, views, method);
    text_printf(&t, "</body></html>\n");
    rc = t.failed ? -ENOMEM : scan_dir_path(path, sizeof(path), dir, -1, SCAN_FILE_REPORT);
    if (rc == 0)
        rc = hal_storage_write_file(st, path, t.s, t.len);
    if (rc != 0)
        snprintf(err, err_len, "%s/report.html: %s", dir, strerror(-rc));
    free(t.s);
    return rc;
}
