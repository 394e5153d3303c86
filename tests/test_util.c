/* Test helpers: quiet logger, simulated rig set-up, and the view-quality measurement. */
#define _POSIX_C_SOURCE 200809L
#include "test_util.h"

#include "scan_job.h"

#include "vec3.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

char test_last_log[512];
int test_error_count;
static char log_history[16384]; /* warnings and errors since test_log_clear(), one per line */
static size_t log_history_len;
static char first_error[512]; /* the first error since test_log_clear() */

int test_files_equal(const char *a, const char *b)
{
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    int same = fa != NULL && fb != NULL;
    while (same) {
        int ca = fgetc(fa), cb = fgetc(fb);
        same = ca == cb;
        if (ca == EOF || cb == EOF)
            break;
    }
    if (fa)
        fclose(fa);
    if (fb)
        fclose(fb);
    return same;
}

int test_temporaries_in(const char *dir)
{
    int n = 0;
    DIR *d = opendir(dir);
    for (struct dirent *e = d ? readdir(d) : NULL; e != NULL; e = readdir(d))
        n += strstr(e->d_name, ".tmp.") != NULL;
    if (d != NULL)
        closedir(d);
    return n;
}

int test_rig_dark(void)
{
    int lit = sim_ctl_line(HAL_GPIO_PROJECTOR_ENABLE);
    for (uint32_t i = 0; i < HAL_MAX_LIGHTS; i++)
        lit |= sim_ctl_line((enum hal_gpio_line)(HAL_GPIO_LIGHT_0 + i));
    return !lit;
}

void test_log_clear(void)
{
    log_history[0] = '\0';
    log_history_len = 0;
    first_error[0] = '\0';
    test_error_count = 0;
}

int test_log_one_error(const char *needle)
{
    if (test_error_count == 1 && strstr(first_error, needle) != NULL)
        return 1;
    fprintf(stderr, "expected one error naming: %s\n%d errors; logged:\n%s", needle,
            test_error_count, log_history);
    return 0;
}

int test_log_has(const char *needle)
{
    if (strstr(log_history, needle) != NULL)
        return 1;
    fprintf(stderr, "not logged: %s\nlogged:\n%s", needle, log_history);
    return 0;
}

void test_rig_log(enum hal_log_level level, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(test_last_log, sizeof(test_last_log), fmt, ap);
    va_end(ap);
    if (level == HAL_LOG_ERROR && test_error_count++ == 0)
        snprintf(first_error, sizeof(first_error), "%s", test_last_log);
    size_t room = sizeof(log_history) - log_history_len;
    if (level <= HAL_LOG_WARN && room > 1) {
        int n = snprintf(log_history + log_history_len, room, "%s\n", test_last_log);
        log_history_len += n > 0 && (size_t)n < room ? (size_t)n : room - 1;
    }
}

int test_rig_load(struct test_rig *t, const char *config_path)
{
    char err[512];
    memset(t, 0, sizeof(*t));
    t->scan = scan_job_views();
    int rc = config_load(&t->cfg, config_path, err, sizeof(err));
    if (rc == 0)
        rc = calib_load(&t->calib, t->cfg.calibration_file, t->cfg.light_count, err, sizeof(err));
    if (rc != 0)
        fprintf(stderr, "test_rig_load: %s\n", err);
    return rc;
}

int test_rig_start(struct test_rig *t)
{
    char err[512];
    t->hal.log = test_rig_log;
    test_error_count = 0;
    struct board_config bc;
    config_board(&t->cfg, &bc);
    int rc = board_init(&t->hal, &bc, &t->calib, err, sizeof(err));
    if (rc != 0) {
        fprintf(stderr, "test_rig_start: %s\n", err);
        return rc;
    }
    rc = scan_open(&t->hal, &t->cfg.camera);
    if (rc == 0)
        rc = hal_table_home(&t->hal.turntable); /* the object at angle 0, as scans start */
    return rc;
}

int test_rig_start_box(struct test_rig *t)
{
    int rc = test_rig_load(t, "config/sim.ini");
    if (rc != 0)
        return rc;
    snprintf(t->cfg.sim.object, sizeof(t->cfg.sim.object), "box");
    t->cfg.sim.segments = 16;
    return test_rig_start(t);
}

void test_rig_stop(struct test_rig *t)
{
    scan_close(&t->hal);
    board_shutdown(&t->hal);
}

int scan_save_cloud_at_turntable_pose(struct test_rig *t, const struct scan_view *view,
                                      const char *path)
{
    struct frame_xform pose;
    frame_object_from_camera(&t->calib, view->angle_mdeg, &pose);
    return scan_save_cloud(&t->hal, view, &pose, path);
}

/* Median width in camera pixels of two projector columns (the finest Gray stripe), from the
 * true column's change between horizontal neighbours on the lit surface. */
static double stripe_width_px(const struct sim_rig *rig)
{
    static uint32_t histogram[4096]; /* columns per pixel, in 1/1024 */
    const struct sim_truth *t = &rig->truth;
    uint32_t count = 0;
    memset(histogram, 0, sizeof(histogram));
    for (uint32_t y = 0; y < rig->height; y++)
        for (uint32_t x = 0; x + 1 < rig->width; x++) {
            size_t i = (size_t)y * rig->width + x;
            if (!t->proj_lit[i] || !t->proj_lit[i + 1])
                continue;
            double du = fabs((double)t->proj_u[i + 1] - t->proj_u[i]) * 1024.0;
            if (du < 4096.0) {
                histogram[(uint32_t)du]++;
                count++;
            }
        }
    for (uint32_t b = 0, seen = 0; b < 4096 && count > 0; b++)
        if ((seen += histogram[b]) * 2 >= count)
            return b > 0 ? 2.0 * 1024.0 / (b + 0.5) : INFINITY;
    return 0.0;
}

/* Is @p column within one of the true column of pixel @p i or of a lit pixel beside it? At a
 * depth edge a blurred camera pixel sees both surfaces, and may rightly decode either. */
static int near_column(const struct sim_rig *rig, size_t i, uint16_t column)
{
    long x = (long)(i % rig->width), y = (long)(i / rig->width);
    for (long dy = -1; dy <= 1; dy++)
        for (long dx = -1; dx <= 1; dx++) {
            long nx = x + dx, ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= (long)rig->width || ny >= (long)rig->height)
                continue;
            size_t j = (size_t)ny * rig->width + (size_t)nx;
            if (rig->truth.proj_lit[j] && fabs(column - floor(rig->truth.proj_u[j] + 0.5)) <= 1.0)
                return 1;
        }
    return 0;
}

void test_measure_view(const struct sim_rig *rig, const struct scan_view *view,
                       struct view_quality *q)
{
    const struct decode_maps *maps = &view->maps;
    const struct tri_range *range = &view->range;
    const struct sim_truth *t = &rig->truth;
    size_t n = (size_t)rig->width * rig->height;
    double sum_sq = 0.0, sum_dist = 0.0, sum_angle = 0.0;
    const struct scan_calib *c = &rig->calib;
    vec3 proj = v3_scale(m3_tmul(c->proj_rot, v3_from(c->proj_trans_mm)), -1.0);
    double min_cos = cos(TEST_MAX_INCIDENCE_DEG * M_PI / 180.0);
    memset(q, 0, sizeof(*q));
    for (size_t i = 0; i < n; i++) {
        int valid = maps->reason[i] == SCAN_VALID;
        if (t->proj_lit[i]) {
            int correct = valid && fabs((double)maps->column[i] - floor(t->proj_u[i] + 0.5)) <= 1.0;
            q->lit++;
            q->lit_correct += (uint32_t)correct;
            q->lit_valid += (uint32_t)valid;
            q->lit_off += (uint32_t)(valid && !correct);
            q->lit_wrong += (uint32_t)(valid && !correct && !near_column(rig, i, maps->column[i]));
            sum_dist += t->pos_cam[3 * i + 2];
            const float *pt = &t->pos_cam[3 * i], *nt = &t->normal_cam[3 * i];
            vec3 to_proj = v3_norm(v3_sub(proj, v3(pt[0], pt[1], pt[2])));
            double cos_in = v3_dot(to_proj, v3(nt[0], nt[1], nt[2]));
            const uint8_t *white = &view->white_rgb[3 * i];
            if (white[0] >= 250 || white[1] >= 250 || white[2] >= 250) {
                q->saturated++;
                q->saturated_correct += (uint32_t)correct;
            }
            if (t->dark[i]) {
                q->dark++;
                q->dark_flagged += (uint32_t)!valid;
                q->dark_correct += (uint32_t)correct;
            } else if (cos_in >= min_cos) {
                q->lit_head_on++;
                q->lit_head_on_correct += (uint32_t)correct;
                q->lit_head_on_valid += (uint32_t)valid;
                q->lit_head_on_off += (uint32_t)(valid && !correct);
                q->lit_head_on_wrong +=
                    (uint32_t)(valid && !correct && !near_column(rig, i, maps->column[i]));
                q->head_on_reason[maps->reason[i]]++;
            }
        }
        if (!valid)
            continue;
        q->valid++;
        if (!t->hit[i]) {
            q->valid_unlit++;
            q->outliers_2mm++;
            q->max_surface_mm = INFINITY;
            continue;
        }
        q->valid_unlit += (uint32_t)!t->proj_lit[i];
        const float *p = &range->xyz_mm[3 * i], *pt = &t->pos_cam[3 * i];
        const float *nt = &t->normal_cam[3 * i];
        const float *ne = &range->normal[3 * i];
        double cos_n = (double)ne[0] * nt[0] + (double)ne[1] * nt[1] + (double)ne[2] * nt[2];
        sum_angle += acos(cos_n > 1.0 ? 1.0 : cos_n < -1.0 ? -1.0 : cos_n) * 180.0 / M_PI;
        double dz = (double)p[2] - pt[2];
        sum_sq += dz * dz;
        /* Distance to the true tangent plane: the true surface, to first order. */
        double plane = fabs(((double)p[0] - pt[0]) * nt[0] + ((double)p[1] - pt[1]) * nt[1] +
                            ((double)p[2] - pt[2]) * nt[2]);
        q->max_surface_mm = plane > q->max_surface_mm ? plane : q->max_surface_mm;
        q->outliers_2mm += (uint32_t)(plane > 2.0);
    }
    q->stripe_px = stripe_width_px(rig);
    q->depth_rms_mm = q->valid ? sqrt(sum_sq / q->valid) : 0.0;
    q->normal_err_deg = q->valid ? sum_angle / q->valid : 0.0;
    q->distance_mm = q->lit ? sum_dist / q->lit : 0.0;
}

static int keep_frame(void *priv, uint32_t pattern, const uint8_t *pixels, uint32_t width,
                      uint32_t height, uint32_t channels)
{
    struct test_frames *f = priv;
    (void)width;
    (void)height;
    if (pattern >= DECODE_MAX_PATTERNS || (channels == 3 && pattern != GRAY_PATTERN_WHITE))
        return 0; /* a colour frame */
    if (f->grey[pattern] == NULL && (f->grey[pattern] = malloc(f->pixels)) == NULL)
        return -ENOMEM;
    if (channels == 3)
        decode_rgb_to_grey(pixels, f->grey[pattern], f->pixels, f->saturation_dn);
    else
        memcpy(f->grey[pattern], pixels, f->pixels);
    return 0;
}

struct scan_frame_sink test_frames_sink(struct test_frames *f)
{
    return (struct scan_frame_sink){.save = keep_frame, .priv = f};
}

void test_frames_free(struct test_frames *f)
{
    for (uint32_t i = 0; i < DECODE_MAX_PATTERNS; i++) {
        free(f->grey[i]);
        f->grey[i] = NULL;
    }
}
