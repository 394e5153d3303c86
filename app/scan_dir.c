/* The scan directory's layout and its small files, read and written in one place. */
#define _POSIX_C_SOURCE 200809L
#include "scan_dir.h"

#include "gray.h"
#include "image_io.h"
#include "ini_schema.h"

#include <errno.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

int scan_dir_path(char *buf, size_t len, const char *dir, int view, const char *name)
{
    int n;
    if (view < 0)
        n = snprintf(buf, len, "%s/%s", dir, name);
    else if (name == NULL)
        n = snprintf(buf, len, "%s/view_%03u", dir, (unsigned)view);
    else
        n = snprintf(buf, len, "%s/view_%03u/%s", dir, (unsigned)view, name);
    return n < 0 || (size_t)n >= len ? -ENAMETOOLONG : 0;
}

int scan_dir_frame_path(char *buf, size_t len, const char *dir, uint32_t view, uint32_t frame)
{
    char name[32];
    snprintf(name, sizeof(name), "frame_%02u.png", (unsigned)frame);
    return scan_dir_path(buf, len, dir, (int)view, name);
}

/* ---- what each frame shows ---- */

/* A colour frame (colour_layout order): its lights and exposure. */
static void colour_frame_name(const struct colour_layout *lay, uint32_t k, char *buf, size_t len)
{
    unsigned us = (unsigned)lay->exposure_us[k];
    if (lay->lights_mask[k] == 0)
        snprintf(buf, len, "dark: projector and lights off, %u us, RGB", us);
    else if (k == COLOUR_FRAME_ALL)
        snprintf(buf, len, "all lights on, projector off, %u us, RGB", us);
    else
        snprintf(buf, len, "light %u alone, %u us, RGB", (unsigned)(k - COLOUR_FRAME_LIGHT0), us);
}

static void pattern_name(uint32_t pattern, const struct gray_layout *l, char *buf, size_t len)
{
    uint32_t k = (pattern - GRAY_PATTERN_FIRST_BIT) / 2u;
    if (pattern == GRAY_PATTERN_WHITE)
        snprintf(buf, len, "white, RGB (the view's colour)");
    else if (pattern == GRAY_PATTERN_BLACK)
        snprintf(buf, len, "black, grey");
    else
        snprintf(buf, len, "%s bit %u of %u%s, grey", k < l->col_bits ? "column" : "row",
                 (unsigned)(k < l->col_bits ? k : k - l->col_bits),
                 (unsigned)(k < l->col_bits ? l->col_bits : l->row_bits),
                 (pattern - GRAY_PATTERN_FIRST_BIT) % 2u ? " inverse" : "");
}

void scan_dir_describe_frames(const struct scan_params *p, const struct scan_calib *c,
                              struct scan_dir_view *v)
{
    struct gray_layout layout;
    struct colour_layout lay;
    gray_layout_for(c->proj_width, c->proj_height, (int)p->decode_rows, &layout);
    colour_layout(&p->colour, c->light_count, &lay);
    uint32_t patterns = gray_layout_count(&layout);
    v->frame_count = patterns + lay.count;
    for (uint32_t f = 0; f < v->frame_count && f < SCAN_DIR_MAX_FRAMES; f++) {
        if (f < patterns)
            pattern_name(f, &layout, v->frame_name[f], SCAN_DIR_FRAME_NAME);
        else
            colour_frame_name(&lay, f - patterns, v->frame_name[f], SCAN_DIR_FRAME_NAME);
    }
}

/* ---- view.ini ---- */

int scan_dir_write_view(const struct hal_storage *st, const char *dir, uint32_t view,
                        const struct scan_dir_view *v)
{
    char text[8192], path[SCAN_DIR_PATH_MAX];
    int len = snprintf(
        text, sizeof(text),
        "; one view of a scan: see docs/scan-format.md\n[view]\nindex = %u\nangle_mdeg = %d\n"
        "started = %s\nfinished = %s\nframes = %u\ncapture_retries = %u\nvalid_points = %u\n"
        "wall_ms = %.1f\n[capture]\nexposure_us = %u\ngain_milli = %u\n"
        "; patterns: projector on, lights off; colour frames as named below\n",
        (unsigned)v->index, (int)v->angle_mdeg, v->started, v->finished, (unsigned)v->frames,
        (unsigned)v->capture_retries, (unsigned)v->valid_points, v->wall_ms,
        (unsigned)v->exposure_us, (unsigned)v->gain_milli);
    for (uint32_t f = 0; f < v->frame_count && (size_t)len < sizeof(text); f++)
        len += snprintf(text + len, sizeof(text) - (size_t)len, "frame_%02u = %s\n", (unsigned)f,
                        v->frame_name[f]);
    if ((size_t)len < sizeof(text))
        len += snprintf(text + len, sizeof(text) - (size_t)len, "[pixels]\n");
    for (unsigned r = 0; r < SCAN_REASON_COUNT && (size_t)len < sizeof(text); r++)
        len += snprintf(text + len, sizeof(text) - (size_t)len, "%s = %u\n", scan_reason_name(r),
                        (unsigned)v->reason_count[r]);
    if ((size_t)len >= sizeof(text))
        return -ENOSPC;
    int rc = scan_dir_path(path, sizeof(path), dir, (int)view, "view.ini");
    return rc != 0 ? rc : hal_storage_write_file(st, path, text, (size_t)len);
}

#define V(member) offsetof(struct scan_dir_view, member)
#define VSZ(member) sizeof(((struct scan_dir_view *)0)->member)

/* Every key view.ini may hold (frame_NN are added at first use). Angles within ten turns. */
#define VIEW_FIXED_KEYS (10u + SCAN_REASON_COUNT)
static struct ini_key view_keys[VIEW_FIXED_KEYS + SCAN_DIR_MAX_FRAMES] = {
    {"view", "index", INI_U32, V(index), 0, 0, 99999, 0, NULL, NULL, "view number"},
    {"view", "angle_mdeg", INI_I32, V(angle_mdeg), 0, -3600000, 3600000, 0, NULL, NULL,
     "turntable angle"},
    {"view", "started", INI_STR, V(started), VSZ(started), 0, 0, 0, "", NULL, "UTC"},
    {"view", "finished", INI_STR, V(finished), VSZ(finished), 0, 0, 0, "", NULL, "UTC"},
    {"view", "frames", INI_U32, V(frames), 0, 0, SCAN_DIR_MAX_FRAMES, 0, NULL, NULL, "frames"},
    {"view", "capture_retries", INI_U32, V(capture_retries), 0, 0, 1e6, 0, "0", NULL, "retries"},
    {"view", "valid_points", INI_U32, V(valid_points), 0, 0, HAL_MAX_PIXELS, 0, "0", NULL,
     "points"},
    {"view", "wall_ms", INI_F64, V(wall_ms), 0, 0, 1e9, 0, "0", NULL, "time"},
    {"capture", "exposure_us", INI_U32, V(exposure_us), 0, 0, 1e8, 0, "0", NULL, "exposure"},
    {"capture", "gain_milli", INI_U32, V(gain_milli), 0, 0, 1e6, 0, "0", NULL, "gain"},
};

static void view_keys_complete(void)
{
    static char frame_keys[SCAN_DIR_MAX_FRAMES][12];
    static int done;
    if (done)
        return;
    for (unsigned r = 0; r < SCAN_REASON_COUNT; r++)
        view_keys[10 + r] = (struct ini_key){"pixels", scan_reason_name(r), INI_U32,
                                             V(reason_count) + r * sizeof(uint32_t), 0, 0,
                                             HAL_MAX_PIXELS, 0, "0", NULL, "pixels"};
    for (unsigned f = 0; f < SCAN_DIR_MAX_FRAMES; f++) {
        snprintf(frame_keys[f], sizeof(frame_keys[f]), "frame_%02u", f);
        view_keys[VIEW_FIXED_KEYS + f] =
            (struct ini_key){"capture", frame_keys[f], INI_STR,
                             V(frame_name) + f * SCAN_DIR_FRAME_NAME, SCAN_DIR_FRAME_NAME, 0, 0,
                             0, "", NULL, "what the frame shows"};
    }
    done = 1;
}

int scan_dir_read_view(const char *dir, uint32_t view, struct scan_dir_view *v, char *err,
                       size_t err_len)
{
    char path[SCAN_DIR_PATH_MAX];
    int rc = scan_dir_path(path, sizeof(path), dir, (int)view, "view.ini");
    if (rc != 0) {
        snprintf(err, err_len, "%s/view_%03u: path too long", dir, (unsigned)view);
        return rc;
    }
    return scan_dir_read_view_file(path, view, v, err, err_len);
}

int scan_dir_read_view_file(const char *path, uint32_t view, struct scan_dir_view *v, char *err,
                            size_t err_len)
{
    view_keys_complete();
    memset(v, 0, sizeof(*v));
    int rc = ini_schema_load(view_keys, sizeof(view_keys) / sizeof(view_keys[0]), v, path, err,
                         err_len);
    if (rc == 0 && v->index != view) {
        snprintf(err, err_len, "%s: [view] index: %u, but this is view %u", path,
                 (unsigned)v->index, (unsigned)view);
        rc = -EINVAL;
    }
    for (v->frame_count = 0; rc == 0 && v->frame_count < SCAN_DIR_MAX_FRAMES &&
                             v->frame_name[v->frame_count][0] != '\0';
         v->frame_count++)
        ;
    return rc;
}

int scan_dir_view_complete(const char *dir, uint32_t view)
{
    static struct scan_dir_view v; /* large; one caller at a time */
    char err[512];
    return scan_dir_read_view(dir, view, &v, err, sizeof(err)) == 0;
}

/* ---- frames ---- */

int scan_dir_write_frame(const struct hal_storage *st, const char *dir, uint32_t view,
                         uint32_t frame, const uint8_t *pixels, uint32_t width, uint32_t height,
                         uint32_t channels)
{
    char path[SCAN_DIR_PATH_MAX];
    int rc = scan_dir_frame_path(path, sizeof(path), dir, view, frame);
    return rc != 0 ? rc : image_write_png(st, path, pixels, width, height, (int)channels);
}

int scan_dir_read_frame(const char *dir, uint32_t view, uint32_t frame, uint8_t *pixels,
                        size_t capacity, uint32_t width, uint32_t height, uint32_t channels,
                        char *err, size_t err_len)
{
    char path[SCAN_DIR_PATH_MAX], why[160];
    uint32_t w = 0, h = 0;
    int rc = scan_dir_frame_path(path, sizeof(path), dir, view, frame);
    if (rc == 0)
        rc = image_read_png(path, pixels, capacity, &w, &h, (int)channels, why, sizeof(why));
    if (rc == 0 && (w != width || h != height)) {
        snprintf(why, sizeof(why), "%ux%u, but this scan's frames are %ux%u", (unsigned)w,
                 (unsigned)h, (unsigned)width, (unsigned)height);
        rc = -EINVAL;
    }
    if (rc != 0)
        snprintf(err, err_len, "%s: %s", path, why);
    return rc;
}

/* ---- the other small files ---- */

int scan_dir_write_registration(const struct hal_storage *st, const char *dir, uint32_t view,
                                const struct icp_report *r)
{
    char text[1024], path[SCAN_DIR_PATH_MAX];
    int len = snprintf(
        text, sizeof(text),
        "; registration of this view against the previous one (docs/scan-format.md)\n"
        "[registration]\nhas_pair = %d\naccepted = %d\noverlap_before = %u\n"
        "coupled_before = %u\ncoupled_share_before = %.4f\noverlap_after = %u\n"
        "coupled_after = %u\ncoupled_share_after = %.4f\nrms_before_mm = %.4f\n"
        "rms_after_mm = %.4f\ncorrection_mm = %.4f\ncorrection_deg = %.4f\n",
        r->has_pair, r->accepted, (unsigned)r->overlap_before, (unsigned)r->coupled_before,
        r->overlap_before ? (double)r->coupled_before / r->overlap_before : 0.0,
        (unsigned)r->overlap_after, (unsigned)r->coupled_after,
        r->overlap_after ? (double)r->coupled_after / r->overlap_after : 0.0, r->rms_before_mm,
        r->rms_after_mm, r->correction_mm, r->correction_deg);
    int rc = scan_dir_path(path, sizeof(path), dir, (int)view, "registration.ini");
    return rc != 0 ? rc : hal_storage_write_file(st, path, text, (size_t)len);
}

static int copy_file(const struct hal_storage *st, const char *from, const char *to)
{
    static char buf[1 << 16]; /* config and calibration files are small */
    FILE *f = fopen(from, "rb");
    if (f == NULL)
        return -errno;
    size_t n = fread(buf, 1, sizeof(buf), f);
    int too_big = !feof(f);
    fclose(f);
    return too_big ? -EFBIG : hal_storage_write_file(st, to, buf, n);
}

int scan_dir_keep_settings(const struct hal_storage *st, const char *config_path,
                           const char *calibration_path, const char *dir)
{
    char path[SCAN_DIR_PATH_MAX];
    int rc = scan_dir_path(path, sizeof(path), dir, -1, "config.ini");
    if (rc == 0)
        rc = copy_file(st, config_path, path);
    if (rc == 0)
        rc = scan_dir_path(path, sizeof(path), dir, -1, "calibration.ini");
    return rc != 0 ? rc : copy_file(st, calibration_path, path);
}
