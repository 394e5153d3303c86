/* The scan directory's layout and its small files, read and written in one place. */
#define _DEFAULT_SOURCE /* flock */
#include "scan_dir.h"
#include "file_posix.h"
#include "reflect.h"

#include "scan.h"

#include "gray.h"
#include "image_io.h"
#include "ini_schema.h"

#include <dirent.h>
#include <ini.h>
#include <pthread.h>
#include <errno.h>
#include <fcntl.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

int scan_dir_path(char *buf, size_t len, const char *dir, int view, const char *name)
{
    int n;
    if (view >= 0 && name != NULL)
        n = snprintf(buf, len, "%s/view_%03u/%s", dir, (unsigned)view, name);
    else if (view >= 0)
        n = snprintf(buf, len, "%s/view_%03u", dir, (unsigned)view);
    else
        n = snprintf(buf, len, "%s/%s", dir, name != NULL ? name : "");
    return n < 0 || (size_t)n >= len ? -ENAMETOOLONG : 0;
}

/* File name endings of each format, and of the ones a reader looks for (older scans: PNG). */
static const char *frame_ending(enum scan_frame_format format, uint32_t channels)
{
    switch (format) {
    case SCAN_FRAMES_PNG:
        return ".png";
    case SCAN_FRAMES_PNM:
        return channels == 3 ? ".ppm" : ".pgm";
    default:
        return channels == 3 ? ".ppm.zst" : ".pgm.zst";
    }
}
static const char *const frame_endings[] = {".pgm.zst", ".ppm.zst", ".png", ".pgm", ".ppm"};

int scan_dir_frame_path(char *buf, size_t len, const char *dir, uint32_t view, uint32_t frame,
                        enum scan_frame_format format, uint32_t channels)
{
    char name[32];
    snprintf(name, sizeof(name), "frame_%02u%s", (unsigned)frame, frame_ending(format, channels));
    return scan_dir_path(buf, len, dir, (int)view, name);
}

int scan_dir_find_frame(char *buf, size_t len, const char *dir, uint32_t view, uint32_t frame)
{
    char name[32];
    struct stat sb;
    for (size_t k = 0; k < sizeof(frame_endings) / sizeof(frame_endings[0]); k++) {
        snprintf(name, sizeof(name), "frame_%02u%s", (unsigned)frame, frame_endings[k]);
        int rc = scan_dir_path(buf, len, dir, (int)view, name);
        if (rc != 0)
            return rc;
        if (stat(buf, &sb) == 0)
            return 0;
        if (errno != ENOENT && errno != ENOTDIR)
            return -errno; /* a link loop, no permission: there, but unreadable; said */
    }
    snprintf(name, sizeof(name), "frame_%02u", (unsigned)frame);
    int rc = scan_dir_path(buf, len, dir, (int)view, name);
    return rc != 0 ? rc : -ENOENT;
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
    else {
        unsigned light = 0; /* the number of its one light */
        while (!(lay->lights_mask[k] >> light & 1u))
            light++;
        snprintf(buf, len, "light %u alone, %u us, RGB", light, us);
    }
}

static void pattern_name(uint32_t pattern, const struct gray_layout *l, int hdr, char *buf,
                         size_t len)
{
    int is_row = 0, inverse = 0;
    uint32_t k = 0;
    gray_layout_pattern(l, pattern, &is_row, &k, &inverse);
    const char *grey =
        hdr ? (l->code == GRAY_CODE_XOR04 ? "XOR-04, grey, HDR merged" : "grey, HDR merged")
            : (l->code == GRAY_CODE_XOR04 ? "XOR-04, grey" : "grey");
    if (pattern == GRAY_PATTERN_WHITE)
        snprintf(buf, len, hdr ? "white, grey, HDR merged" : "white, RGB (the view's colour)");
    else if (pattern == GRAY_PATTERN_BLACK)
        snprintf(buf, len, "black, %s", grey);
    else
        snprintf(buf, len, "%s bit %u of %u%s, %s", is_row ? "row" : "column", (unsigned)k,
                 (unsigned)(is_row ? l->row_bits : l->col_bits), inverse ? " inverse" : "", grey);
}

void scan_dir_describe_frames(const struct scan_params *p, const struct scan_calib *c,
                              struct scan_dir_view *v)
{
    struct gray_layout layout;
    struct colour_layout lay;
    scan_layout(p, c, &layout);
    colour_layout(&p->colour, c->light_count, &lay);
    uint32_t patterns = gray_layout_count(&layout);
    int hdr = p->exposure_count > 0;
    v->frame_count = patterns + lay.count + (hdr ? 1u : 0u);
    for (uint32_t f = 0; f < v->frame_count && f < SCAN_DIR_MAX_FRAMES; f++) {
        if (f < patterns)
            pattern_name(f, &layout, hdr, v->frame_name[f], SCAN_DIR_FRAME_NAME);
        else if (f < patterns + lay.count)
            colour_frame_name(&lay, f - patterns, v->frame_name[f], SCAN_DIR_FRAME_NAME);
        else /* HDR: the white at the camera's exposure */
            snprintf(v->frame_name[f], SCAN_DIR_FRAME_NAME, "white, RGB (the view's colour)");
    }
}

/* ---- view.ini ---- */

#define V(member) offsetof(struct scan_dir_view, member)
#define VSZ(member) sizeof(((struct scan_dir_view *)0)->member)

/* Every key view.ini may hold, in the order it is written: the one table its reader and writer
 * share (the frame_NN and reason keys are added at first use). Angles within ten turns. */
#define VIEW_FIXED_KEYS 10u
#define VIEW_KEYS (VIEW_FIXED_KEYS + SCAN_DIR_MAX_FRAMES + SCAN_REASON_COUNT)
static struct ini_key view_keys[VIEW_KEYS] = {
    {"view", "index", INI_U32, V(index), 0, 0, 99999, 0, NULL, NULL, "view number", NULL, NULL},
    {"view", "angle_mdeg", INI_I32, V(angle_mdeg), 0, -3600000, 3600000, 0, NULL, NULL,
     "turntable angle", NULL, NULL},
    {"view", "started", INI_STR, V(started), VSZ(started), 0, 0, 0, "", NULL, "UTC", NULL, NULL},
    {"view", "finished", INI_STR, V(finished), VSZ(finished), 0, 0, 0, "", NULL, "UTC", NULL, NULL},
    {"view", "frames", INI_U32, V(frames), 0, 0, SCAN_DIR_MAX_CAPTURED, 0, NULL, NULL, "frames",
     NULL, NULL},
    {"view", "capture_retries", INI_U32, V(capture_retries), 0, 0, 1e6, 0, "0", NULL, "retries",
     NULL, NULL},
    {"view", "valid_points", INI_U32, V(valid_points), 0, 0, HAL_MAX_PIXELS, 0, "0", NULL, "points",
     NULL, NULL},
    {"view", "wall_ms", INI_F64, V(wall_ms), 0, 0, 1e9, 0, "0", NULL, "time", "%.1f", NULL},
    {"capture", "exposure_us", INI_U32, V(exposure_us), 0, 0, 1e8, 0, "0", NULL, "exposure", NULL,
     NULL},
    {"capture", "gain_milli", INI_U32, V(gain_milli), 0, 0, 1e6, 0, "0", NULL, "gain", NULL, NULL},
};

/* The frame and reason keys are made once, whichever thread reads or writes a view.ini first
 * (the web server's threads read them too). */
static char frame_keys[SCAN_DIR_MAX_FRAMES][12];
static void make_view_keys(void)
{
    for (unsigned f = 0; f < SCAN_DIR_MAX_FRAMES; f++) {
        snprintf(frame_keys[f], sizeof(frame_keys[f]), "frame_%02u", f);
        view_keys[VIEW_FIXED_KEYS + f] = (struct ini_key){
            "capture",
            frame_keys[f],
            INI_STR,
            V(frame_name) + f * SCAN_DIR_FRAME_NAME,
            SCAN_DIR_FRAME_NAME,
            0,
            0,
            0,
            "",
            NULL,
            "what the frame shows",
            NULL,
            f == 0 ? "patterns: projector on, lights off; colour frames as named below" : NULL};
    }
    for (unsigned r = 0; r < SCAN_REASON_COUNT; r++)
        view_keys[VIEW_FIXED_KEYS + SCAN_DIR_MAX_FRAMES + r] =
            (struct ini_key){"pixels",
                             scan_reason_name(r),
                             INI_U32,
                             V(reason_count) + r * sizeof(uint32_t),
                             0,
                             0,
                             HAL_MAX_PIXELS,
                             0,
                             "0",
                             NULL,
                             "pixels",
                             NULL,
                             NULL};
}

static void view_keys_complete(void)
{
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    pthread_once(&once, make_view_keys);
}

/* A view.ini names the frames the view has: frame_NN of NN < frame_count. */
static int skip_absent_frame(const struct ini_key *k, const void *target)
{
    const struct scan_dir_view *v = target;
    unsigned f;
    return sscanf(k->name, "frame_%u", &f) == 1 && f >= v->frame_count;
}

int scan_dir_write_view(const struct hal_storage *st, const char *dir, uint32_t view,
                        const struct scan_dir_view *v)
{
    static const char header[] = "; one view of a scan: see docs/scan-format.md\n";
    char text[8192], path[SCAN_DIR_PATH_MAX];
    view_keys_complete();
    int len = ini_schema_write(view_keys, VIEW_KEYS, v, header, skip_absent_frame, "", text,
                               sizeof(text));
    if (len < 0)
        return len;
    int rc = scan_dir_path(path, sizeof(path), dir, (int)view, SCAN_FILE_VIEW);
    return rc != 0 ? rc : hal_storage_write_file(st, path, text, (size_t)len);
}

int scan_dir_read_view(const char *dir, uint32_t view, struct scan_dir_view *v, char *err,
                       size_t err_len)
{
    char path[SCAN_DIR_PATH_MAX];
    int rc = scan_dir_path(path, sizeof(path), dir, (int)view, SCAN_FILE_VIEW);
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
    int rc = ini_schema_load(view_keys, VIEW_KEYS, v, path, err, err_len);
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

struct view_count {
    uint32_t views, passes;
};

static int view_count_key(void *user, const char *section, const char *key, const char *value)
{
    struct view_count *c = user;
    if (strcmp(section, "scan") == 0 && strcmp(key, "views") == 0)
        c->views = (uint32_t)strtoul(value, NULL, 10);
    if (strcmp(section, "scan") == 0 && strcmp(key, "passes") == 0)
        c->passes = (uint32_t)strtoul(value, NULL, 10);
    return 1;
}

int scan_dir_view_count(const char *dir, uint32_t *views)
{
    char path[SCAN_DIR_PATH_MAX];
    struct view_count c = {1, 1}; /* the config's defaults of [scan] views and passes */
    int rc = scan_dir_path(path, sizeof(path), dir, -1, SCAN_FILE_CONFIG);
    if (rc == 0 && ini_parse(path, view_count_key, &c) == -1)
        rc = -ENOENT;
    *views = c.views * c.passes;
    return rc;
}

int scan_dir_view_complete(const char *dir, uint32_t view)
{
    struct scan_dir_view *v = malloc(sizeof(*v)); /* large; the web server's threads ask too */
    char err[512];
    int done = v != NULL && scan_dir_read_view(dir, view, v, err, sizeof(err)) == 0;
    free(v);
    return done;
}

uint32_t scan_dir_first_missing(const char *dir, uint32_t views)
{
    uint32_t first = 0;
    while (first < views && scan_dir_view_complete(dir, first))
        first++;
    return first;
}

int scan_dir_make_new(const char *parent, char *out, size_t len, const char **name)
{
    char stamp[32];
    time_t now = time(NULL);
    struct tm tm;
    gmtime_r(&now, &tm);
    strftime(stamp, sizeof(stamp), "%Y-%m-%d_%H%M%S", &tm);
    for (int k = 1; k < 100; k++) {
        int n = k == 1 ? snprintf(out, len, "%s/%s", parent, stamp)
                       : snprintf(out, len, "%s/%s-%d", parent, stamp, k);
        if (n < 0 || (size_t)n >= len)
            return -ENAMETOOLONG;
        if (mkdir(out, 0755) == 0) {
            *name = out + strlen(parent) + 1;
            return 0;
        }
        if (errno != EEXIST)
            return -errno;
    }
    return -EEXIST;
}

int scan_dir_finished(const char *dir)
{
    char path[SCAN_DIR_PATH_MAX];
    return scan_dir_path(path, sizeof(path), dir, -1, SCAN_FILE_SUMMARY) == 0 &&
           access(path, F_OK) == 0;
}

/* ---- frames ---- */

int scan_dir_write_frame(const struct hal_storage *st, const char *dir, uint32_t view,
                         uint32_t frame, const uint8_t *pixels, uint32_t width, uint32_t height,
                         uint32_t channels, enum scan_frame_format format)
{
    char path[SCAN_DIR_PATH_MAX];
    int rc = scan_dir_frame_path(path, sizeof(path), dir, view, frame, format, channels);
    if (rc != 0)
        return rc;
    if (format == SCAN_FRAMES_PNG)
        return image_write_png(st, path, pixels, width, height, (int)channels);
    /* zstd level 1: make bench's frame table (bench/bench_frames.c) */
    return image_write_pnm(st, path, pixels, width, height, (int)channels,
                           format == SCAN_FRAMES_ZSTD ? 1 : 0);
}

int scan_dir_read_frame(const char *dir, uint32_t view, uint32_t frame, uint8_t *pixels,
                        size_t capacity, uint32_t width, uint32_t height, uint32_t channels,
                        char *err, size_t err_len)
{
    char path[SCAN_DIR_PATH_MAX], why[160];
    uint32_t w = 0, h = 0;
    int rc = scan_dir_find_frame(path, sizeof(path), dir, view, frame);
    size_t n = strlen(path);
    if (rc == -ENOENT)
        snprintf(why, sizeof(why), "no such frame (.pgm.zst, .ppm.zst, .png, .pgm or .ppm)");
    else if (rc == 0 && n > 4 && strcmp(path + n - 4, ".png") == 0)
        rc = image_read_png(path, pixels, capacity, &w, &h, (int)channels, why, sizeof(why));
    else if (rc == 0)
        rc = image_read_pnm(path, pixels, capacity, &w, &h, (int)channels, why, sizeof(why));
    if (rc == 0 && (w != width || h != height)) {
        snprintf(why, sizeof(why), "%ux%u, but this scan's frames are %ux%u", (unsigned)w,
                 (unsigned)h, (unsigned)width, (unsigned)height);
        rc = -EINVAL;
    }
    if (rc != 0)
        snprintf(err, err_len, "%s: %s", path, why);
    return rc;
}

int scan_dir_sweep(const struct hal_storage *st, const char *dir, uint32_t views)
{
    char path[SCAN_DIR_PATH_MAX];
    int rc = hal_storage_sweep(st, dir);
    for (uint32_t v = 0; v < views && (rc == 0 || rc == -ENOSYS); v++) {
        rc = scan_dir_path(path, sizeof(path), dir, (int)v, NULL);
        if (rc == 0)
            rc = hal_storage_sweep(st, path);
    }
    return rc == -ENOSYS ? 0 : rc; /* a backend without temporaries has nothing to sweep */
}

/* ---- the other small files ---- */

int scan_dir_write_reflectance(const struct hal_storage *st, const char *dir,
                               const struct reflect_model *m)
{
    char text[8192], path[SCAN_DIR_PATH_MAX];
    size_t len = (size_t)snprintf(
        text, sizeof(text),
        "; reflectance parameters of [colour] method = fit (docs/colour.md): per material\n"
        "; cluster, S = rho cos(theta_i) + specular D(alpha) / cos(theta_r), D the GGX\n"
        "; distribution of alpha = roughness, 1 at its peak (firmware/reflect.h); where\n"
        "; diffuse_roughness is not 0, rho cos(theta_i) is Burley's diffuse of that roughness\n"
        "; (reflect_diffuse); then the\n"
        "; lobe as measured: lobe_specular x the shape lobe, its values at half-angles\n"
        "; 1.2 (k / 15)^2 rad, k = 0 .. 15 (linear between, 0 beyond)\n"
        "[reflectance]\nclusters = %u\n",
        (unsigned)m->count);
    for (uint32_t k = 0; k < m->count && len < sizeof(text); k++) {
        const struct reflect_cluster *c = &m->cluster[k];
        len += (size_t)snprintf(text + len, sizeof(text) - len,
                                "[cluster_%u]\ndiffuse = %.4f, %.4f, %.4f\nspecular = %.4f, %.4f, "
                                "%.4f\nroughness = %.4f\ndiffuse_roughness = %.4f\nsamples = "
                                "%u\nrms = %.4f\n",
                                (unsigned)k, c->centre[0], c->centre[1], c->centre[2],
                                c->specular[0], c->specular[1], c->specular[2], c->roughness,
                                c->retro, (unsigned)c->samples, c->rms);
        if (!c->measured || len >= sizeof(text))
            continue;
        len += (size_t)snprintf(text + len, sizeof(text) - len,
                                "lobe_specular = %.4f, %.4f, %.4f\nlobe =", c->lobe_specular[0],
                                c->lobe_specular[1], c->lobe_specular[2]);
        for (uint32_t n = 0; n < REFLECT_LOBE_NODES && len < sizeof(text); n++)
            len += (size_t)snprintf(text + len, sizeof(text) - len, "%s %.5f", n ? "," : "",
                                    c->lobe[n]);
        if (len < sizeof(text))
            len += (size_t)snprintf(text + len, sizeof(text) - len, "\n");
    }
    if (len >= sizeof(text))
        return -ENAMETOOLONG;
    int rc = scan_dir_path(path, sizeof(path), dir, -1, SCAN_FILE_REFLECTANCE);
    return rc != 0 ? rc : hal_storage_write_file(st, path, text, len);
}

/* registration.ini's turn of view @p v: registered, or kept at the table's angle (turned from
 * it by the paint), and why. */
static const char *turn_said(const struct reg_view *v)
{
    static const char *const kept[2][2] = {
        {"table (the shape does not fix it)",
         "table (too little surface shared with its neighbours)"},
        {"paint (the shape does not fix it)",
         "paint (too little surface shared with its neighbours)"}};
    return v->turn_from_table ? kept[v->turn_by_paint != 0][v->turn_little_shared != 0]
                              : "registered";
}

int scan_dir_write_registration(const struct hal_storage *st, const char *dir, uint32_t view,
                                const struct reg_report *r, const struct reg_view *v,
                                const struct frame_xform *pose)
{
    char text[2048], path[SCAN_DIR_PATH_MAX];
    int len = snprintf(
        text, sizeof(text),
        "; the joint registration of the scan's views, and this view's part (docs/scan-format.md)\n"
        "[registration]\nsolved = %d\naccepted = %d\nrefused = %s\nstride_px = %u\n"
        "iterations = %u\nscore_before_mm = %.4f\nscore_after_mm = %.4f\nrms_mm = %.4f\n"
        "loop_closure_rms_mm = %.4f\naxis_shift_mm = %.4f\naxis_tilt_deg = %.4f\n"
        "worst_view = %u\nworst_rms_mm = %.4f\nsecond_pass_turned_deg = %.3f\n"
        "second_pass_rms_mm = %.4f\nsecond_pass_pairs = %u\nturns_from_table = %u\n"
        "turns_little_shared = %u\nturns_by_paint = %u\naxis_kept_unpaid = %d\naxis_f = %.3f\n"
        "arcs_held = %u\n"
        "moved_at_view = %d\nmoved_views = %u\nmoved_mm = %.3f\nmoved_deg = %.3f\n"
        "moved_placed_by = %s\n"
        "[view]\nreported_angle_deg = %.3f\nangle_deg = %.4f\ncorrection_deg = %.4f\n"
        "turn = %s\nplaced_freely = %d\noverlap = %u\ncoupled = %u\ncoupled_share = %.4f\n"
        "view_rms_mm = %.4f\n",
        r->solved, r->accepted, r->refused, (unsigned)r->stride, (unsigned)r->iterations,
        r->score_before_mm, r->score_after_mm, r->rms_mm, r->loop_rms_mm, r->axis_shift_mm,
        r->axis_tilt_deg, (unsigned)r->worst_view, r->worst_rms_mm, r->second_turned_deg,
        r->second_rms_mm, (unsigned)r->second_coupled, (unsigned)r->turns_from_table,
        (unsigned)r->turns_little_shared, (unsigned)r->turns_by_paint, r->axis_unpaid, r->axis_f,
        (unsigned)r->arcs_held, r->moved_view, (unsigned)r->moved_views, r->moved_mm, r->moved_deg,
        r->moved_view < 0    ? "-"
        : r->moved_by_colour ? "shape and colour"
                             : "shape",
        v->reported_mdeg / 1000.0, v->angle_deg, v->correction_deg, turn_said(v), v->placed_freely,
        (unsigned)v->overlap, (unsigned)v->coupled,
        v->overlap ? (double)v->coupled / v->overlap : 0.0, v->rms_mm);
    const double *m = pose->rot;
    if (len > 0 && (size_t)len < sizeof(text))
        len += snprintf(text + len, sizeof(text) - (size_t)len,
                        "; the pose the view was fused with: p_object = rotation (p_camera - "
                        "origin)\npose_rotation = %.9f, %.9f, %.9f, %.9f, %.9f, %.9f, %.9f, %.9f, "
                        "%.9f\npose_origin_mm = %.6f, %.6f, %.6f\n",
                        m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8], pose->origin.x,
                        pose->origin.y, pose->origin.z);
    if (len < 0 || (size_t)len >= sizeof(text))
        return -ENAMETOOLONG;
    int rc = scan_dir_path(path, sizeof(path), dir, (int)view, SCAN_FILE_REGISTRATION);
    return rc != 0 ? rc : hal_storage_write_file(st, path, text, (size_t)len);
}

/* The @p n numbers after "key =" on line @p line ("a, b, c"). @retval 1 when they are there */
static int numbers_of(const char *line, const char *key, double *v, int n)
{
    size_t kl = strlen(key);
    if (strncmp(line, key, kl) != 0 || line[kl + strspn(line + kl, " ")] != '=')
        return 0;
    const char *p = strchr(line, '=') + 1;
    for (int k = 0; k < n; k++) {
        char *end;
        v[k] = strtod(p, &end);
        if (end == p)
            return 0;
        p = end + strspn(end, " ,");
    }
    return 1;
}

int scan_dir_read_pose(const char *dir, uint32_t view, struct frame_xform *pose)
{
    char path[SCAN_DIR_PATH_MAX], line[512];
    double origin[3];
    int have_rot = 0, have_origin = 0;
    int rc = scan_dir_path(path, sizeof(path), dir, (int)view, SCAN_FILE_REGISTRATION);
    FILE *f = rc == 0 ? file_open_regular(path, "r") : NULL;
    if (f == NULL)
        return rc != 0 ? rc : -errno;
    while (fgets(line, sizeof(line), f) != NULL) {
        have_rot |= numbers_of(line, "pose_rotation", pose->rot, 9);
        have_origin |= numbers_of(line, "pose_origin_mm", origin, 3);
    }
    fclose(f);
    pose->origin = v3(origin[0], origin[1], origin[2]);
    return have_rot && have_origin ? 0 : -EINVAL;
}

/* @p from's bytes with @p extra after them (NULL: none) written durably to @p to. */
static int copy_with(const struct hal_storage *st, const char *from, const char *to,
                     const char *extra)
{
    char buf[1 << 16]; /* config and calibration files are small */
    FILE *f = file_open_regular(from, "rb");
    if (f == NULL)
        return -errno;
    size_t n = fread(buf, 1, sizeof(buf), f);
    int too_big = !feof(f);
    fclose(f);
    size_t more = extra != NULL ? strlen(extra) : 0;
    if (too_big || more > sizeof(buf) - n)
        return -EFBIG;
    if (more > 0)
        memcpy(buf + n, extra, more);
    return hal_storage_write_file(st, to, buf, n + more);
}

int scan_dir_copy_file(const struct hal_storage *st, const char *from, const char *to)
{
    return copy_with(st, from, to, NULL);
}

int scan_dir_keep_settings(const struct hal_storage *st, const char *config_path,
                           const char *calibration_path, const char *dir, const char *chosen)
{
    /* The calibration first: config.ini's presence says the settings are complete (resume
     * takes a directory with config.ini as a scan; a kill between the two left it without its
     * calibration). */
    char path[SCAN_DIR_PATH_MAX];
    int rc = scan_dir_path(path, sizeof(path), dir, -1, SCAN_FILE_CALIBRATION);
    if (rc == 0)
        rc = scan_dir_copy_file(st, calibration_path, path);
    if (rc == 0)
        rc = scan_dir_path(path, sizeof(path), dir, -1, SCAN_FILE_CONFIG);
    return rc != 0 ? rc : copy_with(st, config_path, path, chosen);
}

/* ---- opening: a lock, and what is already there ---- */

/* @retval 1 when @p name is one of the files a scan writes at the top of its directory
 * (the simulator's ground truth among them) */
static int scan_file(const char *name)
{
    static const char *const names[] = {
        SCAN_FILE_CONFIG,      SCAN_FILE_CALIBRATION, SCAN_FILE_MESH_PLY, SCAN_FILE_MESH_OBJ,
        SCAN_FILE_MESH_STL,    SCAN_FILE_MESH_GLB,    SCAN_FILE_MESH_MTL, SCAN_FILE_TEXTURE,
        SCAN_FILE_REFLECTANCE, SCAN_FILE_SUMMARY,     SCAN_FILE_REPORT};
    for (size_t k = 0; k < sizeof(names) / sizeof(names[0]); k++)
        if (strcmp(name, names[k]) == 0)
            return 1;
    return strncmp(name, "truth_", 6) == 0;
}

/* @retval 1 when @p name is a file a view's directory holds */
static int view_file(const char *name)
{
    unsigned frame;
    int end = 0;
    if (sscanf(name, "frame_%2u%n", &frame, &end) == 1 && end == 8)
        for (size_t k = 0; k < sizeof(frame_endings) / sizeof(frame_endings[0]); k++)
            if (strcmp(name + end, frame_endings[k]) == 0)
                return 1;
    return strcmp(name, SCAN_FILE_VIEW) == 0 || strcmp(name, SCAN_FILE_CLOUD) == 0 ||
           strcmp(name, SCAN_FILE_RANGE) == 0 || strcmp(name, SCAN_FILE_TARGET) == 0 ||
           strcmp(name, SCAN_FILE_REGISTRATION) == 0 || strncmp(name, "truth_", 6) == 0;
}

/* @retval 1 when @p name is a view's directory: view_NNN */
static int view_dir(const char *name)
{
    unsigned v;
    char extra;
    return strlen(name) == 8 && sscanf(name, "view_%3u%c", &v, &extra) == 1;
}

/* Check (@p remove 0) or remove (1) every entry of @p dir that a scan writes; the first entry
 * that is not one is named in @p err. What interrupted writes left is swept first: the storage
 * backend knows its temporary files. @retval 0 @retval -EEXIST @retval -errno */
static int scan_entries(const struct hal_storage *storage, const char *dir, int in_view, int remove,
                        char *err, size_t err_len)
{
    int rc_sweep = hal_storage_sweep(storage, dir);
    if (rc_sweep != 0 && rc_sweep != -ENOSYS)
        return rc_sweep;
    DIR *d = opendir(dir);
    if (d == NULL)
        return errno == ENOENT ? 0 : -errno;
    char path[SCAN_DIR_PATH_MAX];
    int rc = 0;
    if (remove && in_view) /* view.ini first: a view cut short here is never taken as finished */
        unlinkat(dirfd(d), SCAN_FILE_VIEW, 0);
    for (struct dirent *e = readdir(d); e != NULL && rc == 0; e = readdir(d)) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        struct stat st;
        if (fstatat(dirfd(d), e->d_name, &st, AT_SYMLINK_NOFOLLOW) != 0) {
            rc = -errno;
            break;
        }
        int is_dir = S_ISDIR(st.st_mode);
        if (!in_view && is_dir && view_dir(e->d_name)) {
            snprintf(path, sizeof(path), "%s/%s", dir, e->d_name);
            rc = scan_entries(storage, path, 1, remove, err, err_len);
            if (rc == 0 && remove && unlinkat(dirfd(d), e->d_name, AT_REMOVEDIR) != 0)
                rc = -errno;
        } else if (!is_dir && (in_view ? view_file(e->d_name) : scan_file(e->d_name))) {
            if (remove && unlinkat(dirfd(d), e->d_name, 0) != 0)
                rc = -errno;
        } else {
            snprintf(err, err_len, "%s/%s is not part of a scan: nothing was replaced", dir,
                     e->d_name);
            rc = -EEXIST;
        }
    }
    closedir(d);
    return rc;
}

/* @retval 1 when @p dir has no entry but . and .. (or does not exist) */
static int empty_dir(const char *dir, char *first, size_t len)
{
    DIR *d = opendir(dir);
    if (d == NULL)
        return 1;
    int empty = 1;
    for (struct dirent *e = readdir(d); e != NULL && empty; e = readdir(d))
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) {
            snprintf(first, len, "%s", e->d_name);
            empty = 0;
        }
    closedir(d);
    return empty;
}

int scan_dir_open(const struct hal_storage *st, const char *dir, enum scan_dir_mode mode,
                  int *lock_fd, char *err, size_t err_len)
{
    *lock_fd = -1;
    int rc = hal_storage_mkdir_p(st, dir);
    if (rc != 0) {
        snprintf(err, err_len, "cannot make the scan directory %s: %s", dir, strerror(-rc));
        return rc;
    }
    /* flock on the directory itself: released when the process ends, however it ends */
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0 || flock(fd, LOCK_EX | LOCK_NB) != 0) {
        rc = errno == EWOULDBLOCK ? -EBUSY : -errno;
        snprintf(err, err_len, "%s: %s", dir,
                 rc == -EBUSY ? "another scanner is using this directory" : strerror(-rc));
        goto out_close;
    }
    char first[256];
    if (mode == SCAN_DIR_NEW && !empty_dir(dir, first, sizeof(first))) {
        snprintf(err, err_len,
                 "%s already holds %s: choose another --out, or --replace to replace the scan "
                 "there ('scanner resume %s' finishes a scan that was stopped)",
                 dir, first, dir);
        rc = -EEXIST;
        goto out_close;
    }
    if (mode == SCAN_DIR_REPLACE) { /* check all first: refuse before anything is removed */
        rc = scan_entries(st, dir, 0, 0, err, err_len);
        if (rc == 0)
            rc = scan_entries(st, dir, 0, 1, err, err_len);
        if (rc != 0 && rc != -EEXIST)
            snprintf(err, err_len, "cannot replace the scan in %s: %s", dir, strerror(-rc));
        if (rc != 0)
            goto out_close;
    }
    *lock_fd = fd;
    return 0;
out_close:
    if (fd >= 0)
        close(fd);
    return rc;
}

void scan_dir_close(int lock_fd)
{
    if (lock_fd >= 0)
        close(lock_fd); /* and with it the lock */
}

int scan_dir_remove(const char *dir, int view, const char *name)
{
    char path[SCAN_DIR_PATH_MAX];
    int rc = scan_dir_path(path, sizeof(path), dir, view, name);
    if (rc == 0 && unlink(path) != 0 && errno != ENOENT)
        rc = -errno;
    return rc;
}

int scan_dir_begin_view(const struct hal_storage *st, const char *dir, uint32_t view)
{
    char path[SCAN_DIR_PATH_MAX];
    int rc = scan_dir_path(path, sizeof(path), dir, (int)view, NULL);
    if (rc == 0)
        rc = hal_storage_mkdir_p(st, path);
    return rc == 0 ? scan_dir_remove(dir, (int)view, SCAN_FILE_VIEW) : rc;
}

unsigned scan_dir_each_warning(const char *dir, unsigned max, size_t line_len,
                               void (*each)(void *priv, const char *line), void *priv)
{
    char path[SCAN_DIR_PATH_MAX], line[1024];
    unsigned count = 0;
    line_len = line_len < sizeof(line) ? line_len : sizeof(line);
    FILE *f = scan_dir_path(path, sizeof(path), dir, -1, SCAN_FILE_WARNINGS) == 0
                  /* a pipe planted there must hang nothing, a link lead nowhere */
                  ? file_open_regular_nolink(path, "r")
                  : NULL;
    for (int c = 0; f != NULL && count < max && fgets(line, (int)line_len, f) != NULL; count++) {
        size_t len = strlen(line);
        if (len > 0 && line[len - 1] == '\n')
            line[--len] = '\0';
        else
            while ((c = fgetc(f)) != EOF && c != '\n') /* the rest of a longer line */
                ;
        each(priv, line);
    }
    if (f != NULL)
        fclose(f);
    return count;
}
