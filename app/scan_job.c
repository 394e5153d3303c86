/* Scan jobs: the view loop shared by live scans and offline re-processing. */
#define _POSIX_C_SOURCE 200809L
#include "scan_job.h"

#include "board.h"
#include "colour.h"
#include "fusion.h"
#include "gray.h"
#include "image_io.h"
#include "scan.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

struct job {
    const struct hal *hal;
    const struct app_config *cfg;
    const struct scan_calib *calib;
    const struct scan_job_opts *opts;
    const char *out_dir;
    uint32_t views;
    double start_ms;
    int tty;
    char view_dir[HAL_MAX_PATH + 32];
};

static double wall_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

static void utc_now(char *buf, size_t len)
{
    time_t t = time(NULL);
    struct tm tm;
    gmtime_r(&t, &tm);
    strftime(buf, len, "%Y-%m-%dT%H:%M:%SZ", &tm);
}

/* ---- progress: a status line on a terminal, plain lines in a log, JSON for a front end ---- */

static void json_string(FILE *out, const char *s)
{
    fputc('"', out);
    for (; *s != '\0'; s++) {
        if (*s == '"' || *s == '\\')
            fprintf(out, "\\%c", *s);
        else if ((unsigned char)*s < 0x20)
            fprintf(out, "\\u%04x", (unsigned)(unsigned char)*s);
        else
            fputc(*s, out);
    }
    fputc('"', out);
}

/* One event. @p view < 0: not about a view. @p done: views finished so far, for the estimate. */
static void progress(struct job *j, const char *event, int view, uint32_t done, const char *detail)
{
    double elapsed_s = (wall_ms() - j->start_ms) / 1000.0;
    double left_s = done > 0 ? elapsed_s / done * (j->views - done) : -1.0;
    if (j->opts->json) {
        printf("{\"event\":\"%s\",\"view\":%d,\"views\":%u,\"elapsed_s\":%.1f,\"left_s\":%.1f,"
               "\"detail\":",
               event, view, (unsigned)j->views, elapsed_s, left_s);
        json_string(stdout, detail);
        printf("}\n");
    } else if (j->tty && view >= 0) {
        /* one status line, rewritten in place; a finished view keeps its line, without the path */
        const char *arrow = NULL; /* the last " -> " introduces the path */
        for (const char *a = strstr(detail, " -> "); a != NULL; a = strstr(a + 1, " -> "))
            arrow = a;
        int shown = arrow != NULL ? (int)(arrow - detail) : (int)strlen(detail);
        printf("\r\033[Kview %d/%u %4.0f s", view + 1, (unsigned)j->views, elapsed_s);
        if (left_s >= 0)
            printf(" (~%.0f s left)", left_s);
        printf("  %s %.*s", event, shown, detail);
        if (strcmp(event, "saved") == 0)
            printf("\n");
    } else if (view >= 0 && strcmp(event, "saved") == 0) {
        printf("view %d of %u: %s\n", view + 1, (unsigned)j->views, detail);
    } else if (view < 0) {
        static const char *const human[][2] = {{"scan_start", "scanning into"},
                                               {"scan_done", "scan finished:"},
                                               {"scan_failed", "scan failed:"},
                                               {"process_start", "processing"},
                                               {"process_done", "process finished:"}};
        const char *text = event;
        for (size_t k = 0; k < sizeof(human) / sizeof(human[0]); k++)
            if (strcmp(event, human[k][0]) == 0)
                text = human[k][1];
        printf("%s %s\n", text, detail);
    }
    fflush(stdout);
}

/* Where the results are, and the peak memory: it must not grow with the number of views. */
static const char *finished_detail(struct job *j, char *buf, size_t len)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    snprintf(buf, len, "%s (mesh: %s/mesh.ply, mesh.obj; peak memory %.1f MB)", j->out_dir,
             j->out_dir, ru.ru_maxrss / 1024.0);
    return buf;
}

/* ---- the scan directory ---- */

static int save_frame(void *priv, uint32_t pattern, const uint8_t *pixels, uint32_t width,
                      uint32_t height, uint32_t channels)
{
    struct job *j = priv;
    char path[HAL_MAX_PATH + 64];
    snprintf(path, sizeof(path), "%s/frame_%02u.png", j->view_dir, (unsigned)pattern);
    return image_write_png(&j->hal->storage, path, pixels, width, height, (int)channels);
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

/* The config and calibration a scan's results came from, kept beside them. */
static int keep_settings(const struct hal_storage *st, const struct app_config *cfg,
                         const char *dir)
{
    char path[HAL_MAX_PATH + 32];
    snprintf(path, sizeof(path), "%s/config.ini", dir);
    int rc = copy_file(st, cfg->path, path);
    snprintf(path, sizeof(path), "%s/calibration.ini", dir);
    return rc != 0 ? rc : copy_file(st, cfg->calibration_file, path);
}

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

static const char *pattern_name(uint32_t pattern, const struct gray_layout *l,
                                const struct colour_layout *lay, char *buf, size_t len)
{
    uint32_t k = (pattern - GRAY_PATTERN_FIRST_BIT) / 2u;
    if (pattern >= gray_layout_count(l)) /* the colour frames after the patterns */
        colour_frame_name(lay, pattern - gray_layout_count(l), buf, len);
    else if (pattern == GRAY_PATTERN_WHITE)
        snprintf(buf, len, "white, RGB (the view's colour)");
    else if (pattern == GRAY_PATTERN_BLACK)
        snprintf(buf, len, "black, grey");
    else
        snprintf(buf, len, "%s bit %u of %u%s, grey", k < l->col_bits ? "column" : "row",
                 (unsigned)(k < l->col_bits ? k : k - l->col_bits),
                 (unsigned)(k < l->col_bits ? l->col_bits : l->row_bits),
                 (pattern - GRAY_PATTERN_FIRST_BIT) % 2u ? " inverse" : "");
    return buf;
}

static int write_view_meta(struct job *j, uint32_t view, const struct scan_view_info *info,
                           const char *started, double ms)
{
    char text[4096], finished[32], name[64];
    utc_now(finished, sizeof(finished));
    struct gray_layout layout;
    struct colour_layout lay;
    scan_layout(&j->cfg->scan, j->calib, &layout);
    colour_layout(&j->cfg->scan.colour, j->calib->light_count, &lay);
    int len = snprintf(
        text, sizeof(text),
        "; one view of a scan: see docs/scan-format.md\n[view]\nindex = %u\nangle_mdeg = %d\n"
        "started = %s\nfinished = %s\nframes = %u\ncapture_retries = %u\nvalid_points = %u\n"
        "wall_ms = %.1f\n[capture]\nexposure_us = %u\ngain_milli = %u\n"
        "; patterns: projector on, lights off; colour frames as named below\n",
        (unsigned)view, (int)info->angle_mdeg, started, finished, (unsigned)info->frames_captured,
        (unsigned)info->capture_retries, (unsigned)info->valid_points, ms,
        (unsigned)j->cfg->camera.exposure_us, (unsigned)j->cfg->camera.gain_milli);
    uint32_t frames = gray_layout_count(&layout) + lay.count;
    for (uint32_t p = 0; p < frames && (size_t)len < sizeof(text); p++)
        len += snprintf(text + len, sizeof(text) - (size_t)len, "frame_%02u = %s\n", (unsigned)p,
                        pattern_name(p, &layout, &lay, name, sizeof(name)));
    len += snprintf(text + len, sizeof(text) - (size_t)len, "[pixels]\n");
    for (unsigned r = 0; r < SCAN_REASON_COUNT && (size_t)len < sizeof(text); r++)
        len += snprintf(text + len, sizeof(text) - (size_t)len, "%s = %u\n", scan_reason_name(r),
                        (unsigned)info->reason_count[r]);
    char path[HAL_MAX_PATH + 64];
    snprintf(path, sizeof(path), "%s/view.ini", j->view_dir);
    return hal_storage_write_file(&j->hal->storage, path, text, (size_t)len);
}

static int write_registration(struct job *j, const struct icp_report *r)
{
    char text[1024], path[HAL_MAX_PATH + 64];
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
    snprintf(path, sizeof(path), "%s/registration.ini", j->view_dir);
    return hal_storage_write_file(&j->hal->storage, path, text, (size_t)len);
}

/* Results of a processed view (its frames, the colour among them, were kept while capturing):
 * its pose (turntable, refined by registration), its point cloud, its part of the fused model. */
static int save_results(struct job *j, const struct scan_view *view, struct icp_report *report)
{
    char path[HAL_MAX_PATH + 64];
    struct frame_xform pose;
    scan_view_pose(j->calib, view, &pose);
    int rc = scan_register_view(&j->cfg->registration, j->calib, view, &pose, report);
    if (rc == 0)
        rc = write_registration(j, report);
    snprintf(path, sizeof(path), "%s/cloud.ply", j->view_dir);
    if (rc == 0)
        rc = scan_save_cloud(j->hal, view, &pose, path);
    if (rc == 0)
        rc = scan_fuse_view(j->calib, view, &pose);
    return rc;
}

static void describe(char *buf, size_t len, const struct scan_view_info *info,
                     const struct icp_report *r, const char *dir)
{
    int n = snprintf(buf, len, "%u points at %.1f deg", (unsigned)info->valid_points,
                     info->angle_mdeg / 1000.0);
    if (r->has_pair && r->overlap_before > 0 && r->overlap_after > 0)
        n += snprintf(buf + n, len - (size_t)n, ", coupled %.1f%% -> %.1f%% of the overlap",
                      100.0 * r->coupled_before / r->overlap_before,
                      100.0 * r->coupled_after / r->overlap_after);
    snprintf(buf + n, len - (size_t)n, " -> %s/cloud.ply", dir);
}

/* The fused model: mesh.ply and mesh.obj in the scan directory. */
static int write_model(struct job *j)
{
    char path[HAL_MAX_PATH + 32], detail[HAL_MAX_PATH + 96];
    uint32_t vertices = 0, triangles = 0;
    progress(j, "meshing", -1, j->views, "marching cubes");
    snprintf(path, sizeof(path), "%s/mesh.ply", j->out_dir);
    int rc = fusion_write_ply(&j->hal->storage, path, &vertices, &triangles);
    if (rc == 0) {
        snprintf(path, sizeof(path), "%s/mesh.obj", j->out_dir);
        rc = fusion_write_obj(&j->hal->storage, path);
    }
    if (rc != 0) {
        j->hal->log(HAL_LOG_ERROR, "cannot write %s: %s", path, strerror(-rc));
        return rc;
    }
    snprintf(detail, sizeof(detail), "%u vertices, %u triangles -> %s/mesh.ply and mesh.obj",
             (unsigned)vertices, (unsigned)triangles, j->out_dir);
    progress(j, "mesh", -1, j->views, detail);
    return 0;
}

static void set_view_dir(struct job *j, uint32_t view)
{
    snprintf(j->view_dir, sizeof(j->view_dir), "%s/view_%03u", j->out_dir, (unsigned)view);
}

/* ---- live ---- */

/* "the N finished views are kept in DIR: scanner resume DIR[ extra] takes the rest" */
static const char *kept_views(const struct job *j, uint32_t v, const char *extra, char *buf,
                              size_t len)
{
    snprintf(buf, len, "the %u finished views are kept in %s: 'scanner resume %s%s' takes the rest",
             (unsigned)v, j->out_dir, j->out_dir, extra);
    return buf;
}

/* The table did not get to view @p v: say where it is and what the controller reports. */
static void table_failed(const struct job *j, uint32_t v, int32_t target_mdeg)
{
    const struct hal *hal = j->hal;
    struct hal_turntable_status st;
    char kept[2 * HAL_MAX_PATH + 96];
    if (hal_table_get_status(&hal->turntable, &st) == 0 && st.alarm_code != 0)
        hal->log(HAL_LOG_ERROR,
                 "view %u: the turntable did not reach %.3f deg: it stopped at %.3f deg with "
                 "alarm %u; once the table turns freely, %s",
                 (unsigned)v, target_mdeg / 1000.0, st.position_mdeg / 1000.0,
                 (unsigned)st.alarm_code, kept_views(j, v, " --clear-alarm", kept, sizeof(kept)));
    else
        hal->log(HAL_LOG_ERROR, "view %u: the turntable did not reach %.3f deg; %s", (unsigned)v,
                 target_mdeg / 1000.0, kept_views(j, v, "", kept, sizeof(kept)));
}

static int live_view(struct job *j, uint32_t v)
{
    const struct hal *hal = j->hal;
    int32_t target = (int32_t)((j->cfg->start_angle_deg + 360.0 * v / j->views) * 1000.0);
    char detail[HAL_MAX_PATH + 160], started[32];
    snprintf(detail, sizeof(detail), "to %.1f deg", target / 1000.0);
    progress(j, "moving", (int)v, v, detail);
    int rc = hal_table_move_to(&hal->turntable, target);
    struct hal_turntable_status st;
    if (rc == 0)
        rc = hal_table_get_status(&hal->turntable, &st); /* the angle the controller reports */
    if (rc != 0) {
        table_failed(j, v, target);
        return rc;
    }
    set_view_dir(j, v);
    rc = hal_storage_mkdir_p(&hal->storage, j->view_dir);
    if (rc != 0)
        return rc;
    utc_now(started, sizeof(started));
    progress(j, "capturing", (int)v, v, "");
    struct scan_frame_sink sink = {save_frame, j};
    struct scan_view view;
    struct scan_view_info info;
    double t0 = wall_ms();
    rc = scan_take_view(hal, &j->cfg->scan, j->calib, st.position_mdeg, &sink, &view, &info);
    if (rc != 0) {
        char kept[2 * HAL_MAX_PATH + 96];
        hal->log(HAL_LOG_ERROR, "view %u at %.3f deg failed: %s; %s", (unsigned)v,
                 st.position_mdeg / 1000.0, rc == -EINTR ? "stopped by request" : strerror(-rc),
                 kept_views(j, v, "", kept, sizeof(kept)));
        return rc;
    }
    progress(j, "saving", (int)v, v, "");
    struct icp_report reg;
    rc = save_results(j, &view, &reg);
    if (rc == 0)
        rc = board_write_view_extras(hal, j->view_dir);
    /* view.ini last: its presence says the view is complete */
    if (rc == 0)
        rc = write_view_meta(j, v, &info, started, wall_ms() - t0);
    if (rc != 0) {
        hal->log(HAL_LOG_ERROR, "cannot save %s: %s", j->view_dir, strerror(-rc));
        return rc;
    }
    describe(detail, sizeof(detail), &info, &reg, j->view_dir);
    progress(j, "saved", (int)v, v + 1, detail);
    return 0;
}

/* Home the table, then take views @p first .. the last, each saved before the next move. */
static int home_and_take_views(struct job *j, uint32_t first)
{
    const struct hal *hal = j->hal;
    progress(j, "homing", (int)first, first, "");
    int rc = 0;
    if (j->opts->clear_alarm && (rc = hal_table_clear_alarm(&hal->turntable)) != 0)
        hal->log(HAL_LOG_ERROR, "cannot clear the turntable's alarm: %s", strerror(-rc));
    if (rc == 0 && (rc = hal_table_home(&hal->turntable)) != 0)
        hal->log(HAL_LOG_ERROR, "the turntable did not home%s",
                 j->opts->clear_alarm ? "" : " (if it reports an alarm: --clear-alarm)");
    for (uint32_t v = first; v < j->cfg->views && rc == 0; v++)
        rc = live_view(j, v);
    return rc;
}

int scan_job_live(const struct hal *hal, const struct app_config *cfg,
                  const struct scan_calib *calib, const struct scan_job_opts *opts)
{
    struct job j = {hal, cfg, calib, opts, opts->out_dir ? opts->out_dir : cfg->output_dir,
                    cfg->views, wall_ms(), isatty(STDOUT_FILENO) && !opts->json, ""};
    char path[HAL_MAX_PATH + 32];
    int rc = hal_storage_mkdir_p(&hal->storage, j.out_dir);
    if (rc == 0)
        rc = keep_settings(&hal->storage, cfg, j.out_dir);
    if (rc != 0) {
        hal->log(HAL_LOG_ERROR, "cannot set up the scan directory %s: %s", j.out_dir,
                 strerror(-rc));
        return rc;
    }
    rc = fusion_begin(&cfg->fusion);
    icp_reset();
    if (rc == 0)
        rc = board_write_scan_extras(hal, j.out_dir);
    if (rc != 0)
        return rc;
    progress(&j, "scan_start", -1, 0, j.out_dir);
    rc = home_and_take_views(&j, 0);
    if (rc == 0)
        rc = write_model(&j);
    if (rc == 0)
        progress(&j, "scan_done", -1, j.views, finished_detail(&j, path, sizeof(path)));
    else if (opts->json)
        progress(&j, "scan_failed", -1, 0, strerror(-rc));
    return rc;
}

/* ---- resume ---- */

int scan_job_load_settings(const char *scan_dir, const char *config_path, struct app_config *cfg,
                           struct scan_calib *calib, char *err, size_t err_len)
{
    char path[HAL_MAX_PATH + 32];
    snprintf(path, sizeof(path), "%s/config.ini", scan_dir);
    int rc = config_load(cfg, config_path ? config_path : path, err, err_len);
    if (rc != 0)
        return rc;
    /* the calibration is the copy kept with the scan, whatever the config named */
    snprintf(cfg->calibration_file, sizeof(cfg->calibration_file), "%s/calibration.ini", scan_dir);
    return calib_load(calib, cfg->calibration_file, cfg->light_count, err, err_len);
}

/* A view is complete once its view.ini, written last, is on disk and readable. */
static int view_complete(const char *scan_dir, uint32_t v)
{
    char path[HAL_MAX_PATH + 32];
    long angle;
    snprintf(path, sizeof(path), "%s/view_%03u/view.ini", scan_dir, (unsigned)v);
    return view_angle_load(path, &angle) == 0;
}

int scan_job_resume(const struct hal *hal, const struct app_config *cfg,
                    const struct scan_calib *calib, const char *scan_dir,
                    const struct scan_job_opts *opts)
{
    struct job j = {hal,      cfg,        calib,     opts,
                    scan_dir, cfg->views, wall_ms(), isatty(STDOUT_FILENO) && !opts->json,
                    ""};
    char detail[64];
    uint32_t first = 0;
    while (first < cfg->views && view_complete(scan_dir, first))
        first++;
    snprintf(detail, sizeof(detail), "%u of %u views kept", (unsigned)first, (unsigned)cfg->views);
    progress(&j, "resume", -1, first, detail);
    if (first == cfg->views)
        return 0;
    int rc = fusion_begin(&cfg->fusion); /* the model comes from scan_job_process afterwards */
    icp_reset();
    return rc != 0 ? rc : home_and_take_views(&j, first);
}

/* ---- offline ---- */

static int process_view(struct job *j, uint32_t v, const char *in_view_dir)
{
    static uint8_t pixels[HAL_MAX_PIXELS * 3];
    const struct hal *hal = j->hal;
    char path[HAL_MAX_PATH + 64];
    long angle;
    snprintf(path, sizeof(path), "%s/view.ini", in_view_dir);
    if (view_angle_load(path, &angle) != 0) {
        hal->log(HAL_LOG_ERROR, "%s: missing or without [view] angle_mdeg", path);
        return -EINVAL;
    }
    int rc = scan_begin_view(&j->cfg->scan, j->calib);
    struct gray_layout layout;
    scan_layout(&j->cfg->scan, j->calib, &layout);
    uint32_t count = gray_layout_count(&layout);
    for (uint32_t p = 0; p < count && rc == 0; p++) {
        uint32_t w, h;
        int channels = p == GRAY_PATTERN_WHITE ? 3 : 1;
        snprintf(path, sizeof(path), "%s/frame_%02u.png", in_view_dir, (unsigned)p);
        rc = image_read_png(path, pixels, sizeof(pixels), &w, &h, channels);
        if (rc == 0 && (w != j->cfg->camera.width || h != j->cfg->camera.height))
            rc = -EINVAL;
        if (rc != 0)
            hal->log(HAL_LOG_ERROR, "%s: %s", path,
                     rc == -EINVAL ? "not a frame of this scan's size" : strerror(-rc));
        else
            rc = scan_feed_frame(p, pixels, (uint32_t)channels, NULL);
    }
    uint32_t lights = scan_light_frame_count(&j->cfg->scan, j->calib);
    for (uint32_t k = 0; k < lights && rc == 0; k++) {
        uint32_t w, h;
        snprintf(path, sizeof(path), "%s/frame_%02u.png", in_view_dir, (unsigned)(count + k));
        rc = image_read_png(path, pixels, sizeof(pixels), &w, &h, 3);
        if (rc == 0 && (w != j->cfg->camera.width || h != j->cfg->camera.height))
            rc = -EINVAL;
        if (rc != 0)
            hal->log(HAL_LOG_ERROR, "%s: %s (needed by [colour] method = %s)", path,
                     rc == -EINVAL ? "not a frame of this scan's size" : strerror(-rc),
                     j->cfg->colour_method);
        else
            rc = scan_feed_light_frame(k, pixels);
    }
    struct scan_view view;
    struct scan_view_info info;
    memset(&info, 0, sizeof(info));
    if (rc == 0)
        rc = scan_finish_view(j->calib, (int32_t)angle, &view, &info);
    set_view_dir(j, v);
    if (rc == 0)
        rc = hal_storage_mkdir_p(&hal->storage, j->view_dir);
    struct icp_report reg;
    if (rc == 0)
        rc = save_results(j, &view, &reg);
    if (rc == 0) {
        char detail[HAL_MAX_PATH + 160];
        describe(detail, sizeof(detail), &info, &reg, j->view_dir);
        progress(j, "saved", (int)v, v + 1, detail);
    }
    return rc;
}

int scan_job_process(const struct hal *hal, const char *scan_dir, const struct scan_job_opts *opts)
{
    static struct app_config cfg;
    static struct scan_calib calib;
    char path[HAL_MAX_PATH + 32], err[512];
    int rc = scan_job_load_settings(scan_dir, opts->config_path, &cfg, &calib, err, sizeof(err));
    if (rc != 0) {
        hal->log(HAL_LOG_ERROR, "%s", err);
        return rc;
    }
    struct job j = {hal, &cfg, &calib, opts, opts->out_dir ? opts->out_dir : scan_dir,
                    cfg.views, wall_ms(), isatty(STDOUT_FILENO) && !opts->json, ""};
    rc = hal_storage_mkdir_p(&hal->storage, j.out_dir);
    if (rc == 0 && opts->out_dir != NULL) /* the results say how they were made */
        rc = keep_settings(&hal->storage, &cfg, j.out_dir);
    if (rc == 0)
        rc = fusion_begin(&cfg.fusion);
    icp_reset();
    progress(&j, "process_start", -1, 0, scan_dir);
    for (uint32_t v = 0; v < cfg.views && rc == 0; v++) {
        char in_dir[HAL_MAX_PATH + 32];
        snprintf(in_dir, sizeof(in_dir), "%s/view_%03u", scan_dir, (unsigned)v);
        rc = process_view(&j, v, in_dir);
    }
    if (rc == 0)
        rc = write_model(&j);
    if (rc == 0)
        progress(&j, "process_done", -1, j.views, finished_detail(&j, path, sizeof(path)));
    return rc;
}
