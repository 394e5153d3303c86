/* The rig as a command brings it up and down: the log, the stop signals, the board and the
 * camera, and the one shutdown that leaves lights and projector off (rig.h). Shared by the
 * scanner program and scanner-calibrate. */
#define _POSIX_C_SOURCE 200809L
#include "rig.h"

#include "board.h"
#include "scan.h"

#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static volatile sig_atomic_t stop_flag;
static struct hal the_hal; /* the rig, once rig_up has brought it up */
static int hal_ready;

void rig_log(enum hal_log_level level, const char *fmt, ...)
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

/* A stop signal, or standard output that can no longer be written: its reader went away (a
 * --json consumer that exited: SIGPIPE is ignored, so the write failed with EPIPE), and a scan
 * nobody can follow stops as it would on a dropped session. */
int rig_stop_requested(void)
{
    if (stop_flag == 0 && ferror(stdout)) {
        stop_flag = 1;
        rig_log(HAL_LOG_WARN, "standard output cannot be written (its reader went away?): "
                              "stopping");
    }
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

void rig_install_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    /* Each of these ends a scan the same way: between frames, then the one shutdown path that
     * puts the rig in its safe state. SIGHUP: the session (ssh, terminal) went away; SIGTSTP
     * (Ctrl-Z) would otherwise freeze the process with the rig lit. */
    const int stops[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGTSTP};
    for (size_t i = 0; i < sizeof(stops) / sizeof(stops[0]); i++)
        sigaction(stops[i], &sa, NULL);
    /* A closed pipe on stdout is an error of the write (EPIPE, see app_stop_requested), not a
     * death without the safe state. */
    sa.sa_handler = SIG_IGN;
    sigaction(SIGPIPE, &sa, NULL);
    sa.sa_handler = on_fatal_signal;
    sigaction(SIGSEGV, &sa, NULL);
    sigaction(SIGBUS, &sa, NULL);
    sigaction(SIGFPE, &sa, NULL);
    sigaction(SIGABRT, &sa, NULL);
}

int rig_load_all(const char *config_path, struct app_config *cfg, struct scan_calib *calib)
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

/* Devices up: logging, signals, the board, the camera; lights and projector off. The one
 * shutdown, rig_down, must follow whatever this returns. @retval 0 or the error (reported) */
int rig_up(const struct app_config *cfg, const struct scan_calib *calib)
{
    char err[512];
    the_hal.log = rig_log;
    the_hal.stop_requested = rig_stop_requested;
    rig_install_signals();
    struct board_config bc;
    config_board(cfg, &bc);
    int rc = board_init(&the_hal, &bc, calib, err, sizeof(err));
    if (rc != 0) {
        fprintf(stderr, "scanner: error: %s\n", err);
        return rc;
    }
    hal_ready = 1;
    return scan_open(&the_hal, &cfg->camera);
}

/* Safe state, camera closed, board released (nothing to do when rig_up failed early). */
void rig_down(void)
{
    if (!hal_ready)
        return;
    scan_close(&the_hal);
    board_shutdown(&the_hal);
    hal_ready = 0;
}

struct hal *rig_hal(void)
{
    return &the_hal;
}
