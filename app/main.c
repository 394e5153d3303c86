/* The scanner command-line program: config, board, one scan, and a safe rig on every exit. */
#define _POSIX_C_SOURCE 200809L
#include "board.h"
#include "config.h"
#include "disk_room.h"
#include "rig.h"
#include "scan.h"
#include "scan_job.h"
#include "white_cal.h"
#include "clock_posix.h"
#include "image_io.h"
#include "mem.h"
#include "memory_posix.h"
#include "patterns.h"
#include "report.h"
#include "scan_dir.h"
#include "storage_posix.h"
#include "thread_posix.h"

#include <errno.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#ifndef SCANNER_VERSION
#define SCANNER_VERSION "0.1.0"
#endif

/* Before the rig is touched: room on the disk for the @p views a scan into @p dir will keep. A
 * scan that fills the disk halfway keeps its finished views, but the person finds out an hour
 * later; said now, one line. @retval 0 room */
static int check_disk_room(const struct app_config *cfg, const char *dir, uint32_t views)
{
    char why[256];
    if (disk_room_check(cfg, dir, views, why, sizeof(why)) == 0)
        return 0;
    fprintf(stderr, "scanner: error: %s: %s\n", dir, why);
    return -ENOSPC;
}

static int cmd_scan(const char *config_path, const struct scan_job_opts *opts)
{
    struct app_config cfg;
    struct scan_calib calib;
    if (rig_load_all(config_path, &cfg, &calib) != 0)
        return 2;
    if (check_disk_room(&cfg, opts->out_dir != NULL ? opts->out_dir : cfg.output_dir,
                        cfg.views * cfg.passes) != 0)
        return 1;
    int rc = rig_up(&cfg, &calib);
    if (rc == 0)
        rc = scan_job_live(rig_hal(), &cfg, &calib, opts);
    rig_down();
    return rc == 0 ? 0 : 1;
}

/* One picture of the object lit by the projector's white, as a PNG (the web page's live view);
 * at @p exposure_us instead of the config's unless 0 (the page's settings, to judge one). */
static int cmd_snapshot(const char *config_path, const char *out, uint32_t exposure_us)
{
    struct app_config cfg;
    struct scan_calib calib;
    const uint8_t *rgb = NULL;
    if (rig_load_all(config_path, &cfg, &calib) != 0)
        return 2;
    if (exposure_us != 0) /* the camera opens at it (rig_up) */
        cfg.camera.exposure_us = cfg.scan.colour.exposure_us = exposure_us;
    int rc = rig_up(&cfg, &calib);
    if (rc == 0)
        rc = scan_snapshot(scan_job_views(), rig_hal(), &cfg.scan, &calib, &rgb);
    rig_down();
    if (rc == 0) {
        struct hal_storage st;
        storage_posix_init(&st);
        rc = image_write_png(&st, out, rgb, cfg.scan.width, cfg.scan.height, 3);
        if (rc != 0)
            fprintf(stderr, "scanner: error: cannot write %s: %s\n", out, strerror(-rc));
    }
    return rc == 0 ? 0 : 1;
}

/* The white target's view from the frames kept in @p from_dir (its first view, taken with every
 * colour frame: a scan with [colour] method multi, or uniform's all-lights frame too), processed
 * with @p cfg and @p calib as calibrate-white's own view would be. @retval 0 @retval -errno
 * (said) */
static int white_view_from(const char *from_dir, const struct app_config *cfg,
                           const struct scan_calib *calib, struct scan_view *view)
{
    struct scan_view_info info;
    static struct scan_dir_view kept; /* its frame list: 2 KiB */
    char err[HAL_MAX_PATH + 256];
    struct scan_ctx *s = scan_job_views();
    int rc = scan_dir_read_view(from_dir, 0, &kept, err, sizeof(err));
    if (rc == -ENOENT) {
        fprintf(stderr, "scanner: error: %s: no view_000/view.ini: not a scan with a view taken\n",
                from_dir);
        return rc;
    }
    if (rc == 0)
        rc = scan_job_feed_view(s, from_dir, 0, &cfg->scan, calib, NULL, err, sizeof(err));
    if (rc == 0) /* multi does not read it; uniform's white reference does */
        rc = scan_job_feed_light_frame(s, from_dir, 0, COLOUR_FRAME_ALL, &cfg->scan, calib, err,
                                       sizeof(err));
    if (rc != 0) {
        fprintf(stderr,
                "scanner: error: %s (the white target's scan: view 0 with every colour "
                "frame, taken with these [camera], [lights] and [colour] settings)\n",
                err);
        return rc;
    }
    rc = scan_finish_view(s, NULL, calib, 0, view, &info);
    if (rc != 0)
        fprintf(stderr, "scanner: error: %s/view_000: cannot be processed (%s)\n", from_dir,
                strerror(-rc));
    return rc;
}

/* One view of a white target with every colour frame (taken now, or kept in @p from_dir):
 * print each method's white_scale. */
static int cmd_calibrate_white(const char *config_path, double target_albedo, const char *from_dir)
{
    struct app_config cfg;
    struct scan_calib calib;
    if (rig_load_all(config_path, &cfg, &calib) != 0)
        return 2;
    if (cfg.light_count == 0) {
        fprintf(stderr, "scanner: error: %s: [lights] count: the white calibration needs lights\n",
                config_path);
        return 2;
    }
    if (!(target_albedo > 0.0 && target_albedo <= 1.0)) {
        fprintf(stderr, "scanner calibrate-white: --albedo: the target's albedo, above 0 and at "
                        "most 1 (0.95 for a white matte target)\n");
        return 2;
    }
    cfg.scan.colour.method = COLOUR_MULTI; /* captures the dark, all-lights and single frames */
    struct scan_view view;
    struct scan_view_info info;
    struct white_cal wc;
    int rc = 0;
    if (from_dir != NULL) {
        rc = white_view_from(from_dir, &cfg, &calib, &view);
        if (rc != 0)
            return 1;
    } else {
        rc = rig_up(&cfg, &calib);
        if (rc == 0)
            rc = hal_table_home(&rig_hal()->turntable);
        if (rc == 0)
            rc = scan_take_view(scan_job_views(), rig_hal(), &cfg.scan, &calib, 0, NULL, &view,
                                &info);
    }
    if (rc == 0) {
        rc = white_cal_from_view(&cfg, &calib, &view, target_albedo, &wc);
        if (rc != 0)
            rig_log(HAL_LOG_ERROR, "no usable white pixels: is the target in view, and not "
                                   "saturated (lower [camera] exposure_us)?");
    }
    if (from_dir == NULL)
        rig_down();
    if (rc != 0)
        return 1;
    static const char *const names[] = {"none", "single", "uniform", "multi"};
    printf("; white reference (target albedo %.3f): put the line of your [colour] method in the "
           "config's [colour] section\n",
           target_albedo);
    for (int m = COLOUR_NONE; m <= COLOUR_MULTI; m++)
        printf("; %s (from %u pixels)\nwhite_scale = %.6f, %.6f, %.6f\n", names[m],
               (unsigned)wc.pixels[m], wc.scale[m][0], wc.scale[m][1], wc.scale[m][2]);
    /* fit's diffuse colour is in multi's units: the same white reference */
    printf("; fit (as multi)\nwhite_scale = %.6f, %.6f, %.6f\n", wc.scale[COLOUR_MULTI][0],
           wc.scale[COLOUR_MULTI][1], wc.scale[COLOUR_MULTI][2]);
    return 0;
}

static void selftest_row(void *ctx, const char *device, const char *where, int rc,
                         const char *detail)
{
    (void)ctx;
    printf("%-11s %-32s %-7s %s\n", device, where, rc == 0 ? "ok" : "MISSING", detail);
}

/* First power-on: each configured device on its own, a table of what works. */
static int cmd_selftest(const char *config_path)
{
    struct app_config cfg;
    struct scan_calib calib;
    char err[512];
    if (config_load(&cfg, config_path, err, sizeof(err)) != 0) {
        fprintf(stderr, "scanner: error: %s\n", err);
        return 2;
    }
    rig_hal()->log = rig_log;
    printf("%-11s %-32s %-7s %s\n", "device", "where", "status", "detail");
    /* A new rig has no calibration yet: say so, and try the devices all the same. */
    int calib_rc = calib_load(&calib, cfg.calibration_file, cfg.light_count, err, sizeof(err));
    if (calib_rc != 0)
        calib.light_count = cfg.light_count;
    selftest_row(NULL, "calibration", cfg.calibration_file, calib_rc, calib_rc ? err : "loaded");
    struct board_config bc;
    config_board(&cfg, &bc);
    int rc = board_selftest(rig_hal(), &bc, &calib, selftest_row, NULL);
    return rc == 0 && calib_rc == 0 ? 0 : 1;
}

/* Offline: only storage, a clock and the log; no device is opened. */
static int cmd_process(const char *scan_dir, const struct scan_job_opts *opts)
{
    struct hal hal;
    memset(&hal, 0, sizeof(hal));
    hal.log = rig_log;
    hal.stop_requested = rig_stop_requested; /* also while resume processes */
    rig_install_signals();
    storage_posix_init(&hal.storage);
    clock_posix_init(&hal.clock);
    thread_posix_init(&hal.thread, 0); /* [scan] threads limits it */
    return scan_job_process(&hal, scan_dir, opts) == 0 ? 0 : 1;
}

/* An interrupted scan: take the views it did not finish, then make every result and the model
 * from the kept frames, as process does (the same model as an uninterrupted scan). */
static int cmd_resume(const char *scan_dir, const struct scan_job_opts *opts)
{
    struct app_config cfg;
    struct scan_calib calib;
    char err[512];
    if (scan_job_load_settings(scan_dir, opts->config_path, 1, &cfg, &calib, err, sizeof(err)) !=
        0) {
        fprintf(stderr, "scanner: error: %s\n", err);
        return 2;
    }
    const uint32_t views = cfg.views * cfg.passes; /* a resume takes them from the first missing */
    if (check_disk_room(&cfg, scan_dir, views - scan_dir_first_missing(scan_dir, views)) != 0)
        return 1;
    int rc = rig_up(&cfg, &calib);
    if (rc == 0)
        rc = scan_job_resume(rig_hal(), &cfg, &calib, scan_dir, opts);
    rig_down();
    if (rc != 0)
        return 1;
    return cmd_process(scan_dir, opts);
}

/* A program installed beside this one, run in its place with the same arguments. */
static int exec_beside(const char *program, char **argv, const char *hint)
{
    char self[HAL_MAX_PATH], path[HAL_MAX_PATH + 32];
    ssize_t n = readlink("/proc/self/exe", self, sizeof(self) - 1);
    if (n <= 0) {
        fprintf(stderr, "scanner: error: cannot find my own program: %s\n", strerror(errno));
        return 1;
    }
    self[n] = '\0';
    char *slash = strrchr(self, '/');
    if (slash != NULL)
        *slash = '\0';
    snprintf(path, sizeof(path), "%s/%s", self, program);
    argv[0] = path;
    execv(path, argv);
    fprintf(stderr, "scanner: error: cannot run %s: %s (%s)\n", path, strerror(errno), hint);
    return 1;
}

/* The calibration (OpenCV) is its own program beside this one, so that a scan never loads it. */
static int cmd_calibrate(int argc, char **argv)
{
    (void)argc;
    return exec_beside("scanner-calibrate", argv,
                       "the calibration needs OpenCV: install Debian's libopencv-dev and "
                       "libopencv-contrib-dev and rebuild");
}

/* The commands: name, what each takes (its usage lines), and what it cannot go without. */
enum needs { NEEDS_NOTHING, NEEDS_CONFIG, NEEDS_DIR };
static const struct command {
    const char *name, *usage;
    enum needs needs;
} commands[] = {
    {"scan",
     "scanner scan --config FILE [--out DIR] [--replace] [--json]   take a scan\n"
     "    (into an empty or new DIR; --replace: replace the scan already there)\n",
     NEEDS_CONFIG},
    {"process",
     "scanner process DIR [--out DIR2 [--replace]] [--config F] [--json]  recompute a scan from\n"
     "    its frames\n",
     NEEDS_DIR},
    {"resume",
     "scanner resume DIR [--config F] [--json] [--clear-alarm]  finish a stopped scan\n"
     "    (--clear-alarm: the turntable's alarm, once its cause is fixed)\n",
     NEEDS_DIR},
    {"calibrate",
     "scanner calibrate --config FILE --out CAL.ini [--dir DIR]  calibrate the rig\n"
     "    (step by step; every capture kept in DIR, default CAL-captures)\n"
     "scanner calibrate --config FILE --from DIR --out CAL.ini  from kept captures\n"
     "scanner calibrate verify --config FILE   scan the sphere, print the errors\n"
     "scanner calibrate board --config FILE --out BASE  the board to print\n"
     "    (BASE.png at 300 dpi, BASE.svg at true size)\n",
     NEEDS_CONFIG},
    {"calibrate-white",
     "scanner calibrate-white --config FILE [--albedo A] [--from DIR]  white reference scales\n"
     "    (--from: from the white target's scan kept in DIR, its first view)\n",
     NEEDS_CONFIG},
    {"check-config",
     "scanner check-config --config FILE    check a config, its calibration and the files it "
     "names\n",
     NEEDS_CONFIG},
    {"patterns",
     "scanner patterns --config FILE --out DIR  the projector's pattern sequence as PNG files,\n"
     "    for a projector that stores its own (DLP pattern memory)\n",
     NEEDS_CONFIG},
    {"selftest", "scanner selftest --config FILE        try each configured device (new rig)\n",
     NEEDS_CONFIG},
    {"report", "scanner report DIR                    write DIR/report.html again\n", NEEDS_DIR},
    {"serve",
     "scanner serve --config FILE [--listen ADDR:PORT] [--token-file F]  the web interface\n"
     "    (default http://127.0.0.1:8080; scanner serve --help says more)\n",
     NEEDS_CONFIG},
    {"snapshot",
     "scanner snapshot --config FILE --out FILE.png [--exposure-us N]  one picture, projector "
     "white\n",
     NEEDS_CONFIG},
    {"config-doc", "scanner config-doc                    print the config reference (Markdown)\n",
     NEEDS_NOTHING},
};

static const struct command *find_command(const char *name)
{
    for (size_t k = 0; k < sizeof(commands) / sizeof(commands[0]); k++)
        if (strcmp(name, commands[k].name) == 0)
            return &commands[k];
    return NULL;
}

/* Usage lines, each indented under "usage: ": of one command, or of them all. */
static void usage_of(FILE *out, const struct command *only)
{
    int first = 1;
    for (size_t k = 0; k < sizeof(commands) / sizeof(commands[0]); k++) {
        if (only != NULL && only != &commands[k])
            continue;
        for (const char *line = commands[k].usage; *line != '\0';) {
            size_t len = strcspn(line, "\n");
            fprintf(out, "%s%.*s\n", first ? "usage: " : "       ", (int)len, line);
            first = 0;
            line += len + (line[len] == '\n');
        }
    }
    if (only == NULL)
        fprintf(out, "       scanner --version\n"
                     "       scanner --help, scanner COMMAND --help\n");
}

static void usage(FILE *out)
{
    usage_of(out, NULL);
}

static int is_help(const char *arg)
{
    return strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0;
}

/* The command line's words before any work: help, an unknown command, an unknown or missing
 * option said plainly. @retval -1 go on @retval the exit status (0 help, 2 a mistake) */
static int check_command_line(int argc, char **argv, const struct command **cmd)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (is_help(argv[1]) || strcmp(argv[1], "help") == 0) {
        const struct command *c = argc > 2 ? find_command(argv[2]) : NULL;
        if (argc > 2 && c == NULL) {
            fprintf(stderr, "scanner: unknown command '%s' (scanner --help lists them)\n", argv[2]);
            return 2;
        }
        usage_of(stdout, c);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0)
        return -1;
    *cmd = find_command(argv[1]);
    if (*cmd == NULL) {
        fprintf(stderr, "scanner: unknown command '%s' (scanner --help lists them)\n", argv[1]);
        return 2;
    }
    for (int i = 2; i < argc && strcmp((*cmd)->name, "serve") != 0; i++) /* its own --help */
        if (is_help(argv[i])) {
            usage_of(stdout, *cmd);
            return 0;
        }
    return -1;
}

/* A required option or operand the command line lacks: named, with the command's usage. */
static int missing(const struct command *cmd, const char *what)
{
    fprintf(stderr, "scanner %s: %s is required\n", cmd->name, what);
    usage_of(stderr, cmd);
    return 2;
}

int main(int argc, char **argv)
{
    const char *config_path = NULL, *scan_dir = NULL;
    struct scan_job_opts opts = {0, NULL, NULL, 0, 0};
    double white_albedo = 0.95;        /* a typical white reference target */
    const char *white_from = NULL;     /* calibrate-white --from: a kept scan of the target */
    uint32_t snapshot_exposure_us = 0; /* snapshot --exposure-us: 0 the config's */
    const struct command *cmd = NULL;
    int status = check_command_line(argc, argv, &cmd);
    if (status >= 0)
        return status;
    /* the big static buffers mapped as they are begun, given back once done with */
    static const struct mem_platform memory = {memory_posix_prefault, memory_posix_release};
    mem_use(&memory);
    if (strcmp(argv[1], "--version") == 0) {
        printf("scanner %s (HAL=%s)\n", SCANNER_VERSION, board_name());
        return 0;
    }
    if (strcmp(argv[1], "calibrate") == 0)
        return cmd_calibrate(argc, argv);
    /* The web server (civetweb) is its own program too: a scan never loads it. */
    if (strcmp(argv[1], "serve") == 0)
        return exec_beside("scanner-web", argv,
                           "the web interface needs civetweb: install Debian's libcivetweb-dev "
                           "and libcjson-dev and rebuild");
    int first = 2;
    if (cmd->needs == NEEDS_DIR && argc > 2 && argv[2][0] != '-') {
        scan_dir = argv[2];
        first = 3;
    }
    for (int i = first; i < argc; i++) {
        if (strcmp(argv[i], "--config") == 0 && i + 1 < argc)
            config_path = argv[++i];
        else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc)
            opts.out_dir = argv[++i];
        else if (strcmp(argv[i], "--json") == 0)
            opts.json = 1;
        else if (strcmp(argv[i], "--clear-alarm") == 0 && strcmp(argv[1], "resume") == 0)
            opts.clear_alarm = 1;
        else if (strcmp(argv[i], "--replace") == 0 &&
                 (strcmp(argv[1], "scan") == 0 || strcmp(argv[1], "process") == 0))
            opts.replace = 1;
        else if (strcmp(argv[i], "--albedo") == 0 && i + 1 < argc) {
            char *end;
            white_albedo = strtod(argv[++i], &end);
            if (end == argv[i] || *end != '\0')
                white_albedo = -1.0; /* refused with the range below */
        } else if (strcmp(argv[i], "--from") == 0 && i + 1 < argc &&
                   strcmp(argv[1], "calibrate-white") == 0)
            white_from = argv[++i];
        else if (strcmp(argv[i], "--exposure-us") == 0 && i + 1 < argc &&
                 strcmp(argv[1], "snapshot") == 0) {
            char *end;
            unsigned long v = strtoul(argv[++i], &end, 10);
            if (end == argv[i] || *end != '\0' || argv[i][0] == '-' || v < 10 || v > 10000000) {
                fprintf(stderr,
                        "scanner snapshot: --exposure-us '%s': a whole number of "
                        "microseconds from 10 to 10000000 ([camera] exposure_us's range)\n",
                        argv[i]);
                return 2;
            }
            snapshot_exposure_us = (uint32_t)v;
        } else {
            int valued = strcmp(argv[i], "--config") == 0 || strcmp(argv[i], "--out") == 0 ||
                         strcmp(argv[i], "--albedo") == 0 ||
                         strcmp(argv[i], "--exposure-us") == 0 || strcmp(argv[i], "--from") == 0;
            fprintf(stderr, "scanner %s: %s '%s'\n", cmd->name,
                    valued ? "a value is missing after" : "unknown argument", argv[i]);
            usage_of(stderr, cmd);
            return 2;
        }
    }
    if (strcmp(argv[1], "config-doc") == 0) {
        config_print_doc(stdout);
        return 0;
    }
    if (cmd->needs == NEEDS_DIR && scan_dir == NULL)
        return missing(cmd, "the scan directory DIR");
    if (strcmp(argv[1], "process") == 0) {
        opts.config_path = config_path; /* optional: other settings for the same frames */
        return cmd_process(scan_dir, &opts);
    }
    if (strcmp(argv[1], "report") == 0) {
        struct hal_storage st;
        char err[HAL_MAX_PATH + 128];
        storage_posix_init(&st);
        if (report_write(&st, scan_dir, err, sizeof(err)) != 0) {
            fprintf(stderr, "scanner: error: %s\n", err);
            return 1;
        }
        printf("%s/report.html\n", scan_dir);
        return 0;
    }
    if (strcmp(argv[1], "resume") == 0) {
        opts.config_path = config_path; /* optional: the scan's config where it was written */
        return cmd_resume(scan_dir, &opts);
    }
    if (config_path == NULL)
        return missing(cmd, "--config FILE");
    if (strcmp(argv[1], "check-config") == 0) {
        struct app_config cfg;
        struct scan_calib calib;
        char err[1024];
        if (rig_load_all(config_path, &cfg, &calib) != 0)
            return 2;
        if (config_check_files(&cfg, err, sizeof(err)) != 0) {
            fprintf(stderr, "scanner: error: %s\n", err);
            return 2;
        }
        char why[1024];
        if (calib_read_weak(cfg.calibration_file, why, sizeof(why)))
            fprintf(stderr,
                    "scanner: warning: %s: the calibration is weak: %s (scan with it, or "
                    "calibrate again with those placements added)\n",
                    cfg.calibration_file, why);
        printf("%s: ok\n", config_path);
        return 0;
    }
    if (strcmp(argv[1], "patterns") == 0) {
        struct app_config cfg;
        struct scan_calib calib;
        struct hal_storage st;
        if (opts.out_dir == NULL)
            return missing(cmd, "--out DIR");
        if (rig_load_all(config_path, &cfg, &calib) != 0)
            return 2;
        storage_posix_init(&st);
        return patterns_write(&st, &cfg, &calib, opts.out_dir) == 0 ? 0 : 1;
    }
    if (strcmp(argv[1], "scan") == 0)
        return cmd_scan(config_path, &opts);
    if (strcmp(argv[1], "snapshot") == 0)
        return opts.out_dir == NULL ? missing(cmd, "--out FILE.png")
                                    : cmd_snapshot(config_path, opts.out_dir, snapshot_exposure_us);
    if (strcmp(argv[1], "calibrate-white") == 0)
        return cmd_calibrate_white(config_path, white_albedo, white_from);
    return cmd_selftest(config_path);
}
