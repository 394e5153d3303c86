/* The scanner command-line program: config, board, one scan, and a safe rig on every exit. */
#define _POSIX_C_SOURCE 200809L
#include "board.h"
#include "config.h"
#include "image_io.h"
#include "scan.h"

#include <errno.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifndef SCANNER_VERSION
#define SCANNER_VERSION "0.1.0"
#endif

static volatile sig_atomic_t stop_flag;
static struct hal the_hal;
static int hal_ready;

static void app_log(enum hal_log_level level, const char *fmt, ...)
{
    static const char *const tag[] = {"error", "warning", "info", "debug"};
    va_list ap;
    if (level == HAL_LOG_DEBUG && getenv("SCANNER_DEBUG") == NULL)
        return;
    fprintf(stderr, "scanner: %s: ", tag[level]);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

static int app_stop_requested(void)
{
    return stop_flag != 0;
}

static void on_stop_signal(int sig)
{
    (void)sig;
    stop_flag = 1; /* the scan loop sees it between frames and shuts down in order */
}

/* Fatal signals: one shutdown that leaves lights and projector off, then die as asked. */
static void on_fatal_signal(int sig)
{
    if (hal_ready)
        hal_safe_state(&the_hal);
    signal(sig, SIG_DFL);
    raise(sig);
}

static void install_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sa.sa_handler = on_fatal_signal;
    sigaction(SIGSEGV, &sa, NULL);
    sigaction(SIGBUS, &sa, NULL);
    sigaction(SIGFPE, &sa, NULL);
    sigaction(SIGABRT, &sa, NULL);
}

static double wall_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
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

static int write_view_meta(const struct hal_storage *st, const char *path,
                           const struct scan_view_info *info, double ms)
{
    char text[1024];
    int len = snprintf(text, sizeof(text),
                       "; one view of a scan: see docs/scan-format.md\n[view]\nangle_mdeg = %d\n"
                       "frames = %u\ncapture_retries = %u\nvalid_points = %u\nwall_ms = %.1f\n"
                       "[pixels]\n",
                       (int)info->angle_mdeg, (unsigned)info->frames_captured,
                       (unsigned)info->capture_retries, (unsigned)info->valid_points, ms);
    for (unsigned r = 0; r < SCAN_REASON_COUNT && len > 0 && (size_t)len < sizeof(text); r++)
        len += snprintf(text + len, sizeof(text) - (size_t)len, "%s = %u\n", scan_reason_name(r),
                        (unsigned)info->reason_count[r]);
    return hal_storage_write_file(st, path, text, (size_t)len);
}

/* Save everything of a finished view: cloud, colour, metadata, and the board's extras. */
static int save_view(const struct app_config *cfg, const struct scan_calib *calib,
                     const char *view_dir, const struct scan_view_info *info, double ms)
{
    char path[HAL_MAX_PATH + 32];
    int rc = hal_storage_mkdir_p(&the_hal.storage, view_dir);
    if (rc == 0) {
        snprintf(path, sizeof(path), "%s/cloud.ply", view_dir);
        rc = scan_save_cloud(&the_hal, calib, path);
    }
    if (rc == 0) {
        snprintf(path, sizeof(path), "%s/colour.png", view_dir);
        rc = image_write_png(&the_hal.storage, path, scan_colour_frame(), cfg->camera.width,
                             cfg->camera.height, 3);
    }
    if (rc == 0)
        rc = board_write_view_extras(&the_hal, view_dir);
    if (rc == 0) {
        snprintf(path, sizeof(path), "%s/view.ini", view_dir);
        rc = write_view_meta(&the_hal.storage, path, info, ms);
    }
    if (rc != 0)
        app_log(HAL_LOG_ERROR, "cannot save %s: %s", view_dir, strerror(-rc));
    return rc;
}

static int run_views(const struct app_config *cfg, const struct scan_calib *calib)
{
    for (uint32_t v = 0; v < cfg->views; v++) {
        int32_t angle_mdeg = (int32_t)((cfg->start_angle_deg + 360.0 * v / cfg->views) * 1000.0);
        int rc = hal_table_move_to(&the_hal.turntable, angle_mdeg);
        if (rc != 0) {
            app_log(HAL_LOG_ERROR, "view %u: the turntable did not reach %.3f deg", (unsigned)v,
                    angle_mdeg / 1000.0);
            return rc;
        }
        struct scan_view_info info;
        double t0 = wall_ms();
        rc = scan_view(&the_hal, &cfg->scan, calib, angle_mdeg, &info);
        double ms = wall_ms() - t0;
        if (rc != 0) {
            app_log(HAL_LOG_ERROR, "view %u at %.1f deg failed: %s", (unsigned)v,
                    angle_mdeg / 1000.0, rc == -EINTR ? "stopped by request" : strerror(-rc));
            return rc;
        }
        char view_dir[HAL_MAX_PATH + 16];
        snprintf(view_dir, sizeof(view_dir), "%s/view_%03u", cfg->output_dir, (unsigned)v);
        rc = save_view(cfg, calib, view_dir, &info, ms);
        if (rc != 0)
            return rc;
        printf(
            "view %u of %u: %u points (%.1f%% of pixels), %u frames in %.0f ms -> %s/cloud.ply\n",
            (unsigned)v + 1, (unsigned)cfg->views, (unsigned)info.valid_points,
            100.0 * info.valid_points / ((double)cfg->camera.width * cfg->camera.height),
            (unsigned)info.frames_captured, ms, view_dir);
    }
    return 0;
}

static int load_all(const char *config_path, struct app_config *cfg, struct scan_calib *calib)
{
    char err[512];
    int rc = config_load(cfg, config_path, err, sizeof(err));
    if (rc == 0)
        rc = calib_load(calib, cfg->calibration_file, cfg->light_count, err, sizeof(err));
    if (rc == 0)
        rc = scan_check(&cfg->scan, calib, err, sizeof(err));
    if (rc != 0)
        fprintf(stderr, "scanner: error: %s\n", err);
    return rc;
}

static int cmd_scan(const char *config_path, const char *out_dir)
{
    static struct app_config cfg;
    static struct scan_calib calib;
    char err[512], path[HAL_MAX_PATH + 32];
    if (load_all(config_path, &cfg, &calib) != 0)
        return 2;
    if (out_dir != NULL)
        snprintf(cfg.output_dir, sizeof(cfg.output_dir), "%s", out_dir);
    the_hal.log = app_log;
    the_hal.stop_requested = app_stop_requested;
    install_signals();
    int rc = board_init(&the_hal, &cfg, &calib, err, sizeof(err));
    if (rc != 0) {
        fprintf(stderr, "scanner: error: %s\n", err);
        return 1;
    }
    hal_ready = 1;
    rc = hal_storage_mkdir_p(&the_hal.storage, cfg.output_dir);
    if (rc != 0)
        app_log(HAL_LOG_ERROR, "cannot create %s: %s", cfg.output_dir, strerror(-rc));
    if (rc == 0) {
        snprintf(path, sizeof(path), "%s/config.ini", cfg.output_dir);
        rc = copy_file(&the_hal.storage, config_path, path);
        snprintf(path, sizeof(path), "%s/calibration.ini", cfg.output_dir);
        if (rc == 0)
            rc = copy_file(&the_hal.storage, cfg.calibration_file, path);
        if (rc != 0)
            app_log(HAL_LOG_ERROR, "cannot copy the config into %s: %s", cfg.output_dir,
                    strerror(-rc));
    }
    if (rc == 0)
        rc = scan_open(&the_hal, &cfg.camera);
    if (rc == 0) {
        rc = hal_table_home(&the_hal.turntable);
        if (rc != 0)
            app_log(HAL_LOG_ERROR, "the turntable did not home");
    }
    if (rc == 0)
        rc = run_views(&cfg, &calib);
    scan_close(&the_hal);
    board_shutdown(&the_hal);
    hal_ready = 0;
    if (rc == 0)
        printf("scan finished: %s (point cloud of view 0: %s/view_000/cloud.ply; open it in "
               "MeshLab, CloudCompare, Blender or Open3D)\n",
               cfg.output_dir, cfg.output_dir);
    return rc == 0 ? 0 : 1;
}

static void usage(FILE *out)
{
    fprintf(out,
            "usage: scanner scan --config FILE [--out DIR]   take a scan\n"
            "       scanner check-config --config FILE      check a config and its calibration\n"
            "       scanner config-doc                      print the config reference (Markdown)\n"
            "       scanner --version\n");
}

int main(int argc, char **argv)
{
    const char *config_path = NULL, *out_dir = NULL;
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    for (int i = 2; i < argc; i++) {
        if (strcmp(argv[i], "--config") == 0 && i + 1 < argc)
            config_path = argv[++i];
        else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc)
            out_dir = argv[++i];
        else {
            fprintf(stderr, "scanner: unknown argument '%s'\n", argv[i]);
            usage(stderr);
            return 2;
        }
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("scanner %s (HAL=%s)\n", SCANNER_VERSION, board_name());
        return 0;
    }
    if (strcmp(argv[1], "config-doc") == 0) {
        config_print_doc(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--help") == 0) {
        usage(stdout);
        return 0;
    }
    if (config_path == NULL) {
        usage(stderr);
        return 2;
    }
    if (strcmp(argv[1], "check-config") == 0) {
        static struct app_config cfg;
        static struct scan_calib calib;
        if (load_all(config_path, &cfg, &calib) != 0)
            return 2;
        printf("%s: ok\n", config_path);
        return 0;
    }
    if (strcmp(argv[1], "scan") == 0)
        return cmd_scan(config_path, out_dir);
    usage(stderr);
    return 2;
}
