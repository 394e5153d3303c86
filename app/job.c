/* A scan job's common parts (job.h): its state, clocks, output directory and the one way a
 * failed write is said. */
#define _POSIX_C_SOURCE 200809L
#include "job.h"

#include "atlas.h"

#include "board.h"
#include "clock_posix.h"
#include "reflect.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

double job_wall_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

void job_utc_now(char *buf, size_t len)
{
    time_t t = time(NULL);
    struct tm tm;
    gmtime_r(&t, &tm);
    strftime(buf, len, "%Y-%m-%dT%H:%M:%SZ", &tm);
}

/* The registration's samples and solution: a job at a time per process (REG_MAX_CELLS x 28
 * bytes, mapped as views are added). */
static struct reg_ctx registration;
/* The reflectance's samples and model ([colour] method = fit), likewise. */
static struct reflect_pool reflectance;
/* One view's frames, maps and colour, likewise: the process's only one (the commands that take a
 * single view outside a job borrow it through scan_job_views). */
static struct scan_ctx views;
/* Its colour frames, and the volume the views are fused in and the mesh made from, in one
 * memory: the frames are read while the views are taken and, by [colour] method = fit, before
 * the fusion begins (job_make_model); the volume from fusion_begin on, which sets every part of
 * it it reads. Why: they are the largest buffers after the views' (189 and 380 MiB at the
 * default limits, 1,023 and 639 MiB at LIMITS=large), never needed at once; a job lends the
 * frames to the volume (job.h: frames_lent) and reads no colour frame after. */
static union {
    struct scan_light_frames light;
    struct fusion_volume volume;
} frames_or_volume;
/* The model's texture atlas and its work space, likewise. */
static struct atlas texture;

struct scan_ctx *scan_job_views(void)
{
    scan_use_light_frames(&views, &frames_or_volume.light);
    return &views;
}

void job_lend_frames(struct job *j)
{
    scan_release_frames(j->scan);
    scan_use_light_frames(j->scan, NULL); /* a colour frame read now is refused, not written */
    j->frames_lent = 1;
}

void job_init(struct job *j, const struct hal *hal, const struct app_config *cfg,
              const struct scan_calib *calib, const struct scan_job_opts *opts, const char *out_dir)
{
    *j = (struct job){.hal = hal,
                      .cfg = cfg,
                      .calib = calib,
                      .opts = opts,
                      .out_dir = out_dir,
                      .views = cfg->views * cfg->passes, /* every pass's */
                      .start_ms = job_wall_ms(),
                      .start_cpu_s = clock_posix_process_cpu_s(),
                      .start_sim_cpu_s = board_simulator_cpu_s(),
                      .start_thread_cpu_s = clock_posix_thread_cpu_s(),
                      .scan = scan_job_views(),
                      .reg = &registration,
                      .pool = &reflectance,
                      .vol = &frames_or_volume.volume,
                      .atlas = &texture,
                      .tty = isatty(STDOUT_FILENO) && !opts->json};
    if (hal_clock_now_us(&hal->clock, &j->start_rig_us) != 0)
        j->start_rig_us = 0;
}

/* The CPU the scanner spent since the job began, the simulator's rendering (@p sim_s, out)
 * left out. */
double job_own_cpu_s(const struct job *j, double *sim_s)
{
    double cpu = clock_posix_process_cpu_s() - j->start_cpu_s;
    *sim_s = board_simulator_cpu_s() - j->start_sim_cpu_s;
    return cpu - *sim_s;
}

/* The process's peak resident memory: it must not grow with the number of views. */
double job_peak_memory_mb(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss / 1024.0;
}

/* A write into the view's directory that failed, said once, naming the file.
 * @retval @p rc */
int job_write_failed_at(const struct job *j, const char *dir, const char *name, int rc)
{
    if (rc != 0)
        j->hal->log(HAL_LOG_ERROR, "cannot write %s/%s: %s", dir, name, strerror(-rc));
    return rc;
}

/* Lock the job's output directory against a second scanner (checking what it holds by
 * @p mode) and sweep what a kill left there; a refusal is said once. */
int job_open_out(struct job *j, enum scan_dir_mode mode, int *lock_fd)
{
    char err[SCAN_DIR_PATH_MAX + 256];
    int rc = scan_dir_open(&j->hal->storage, j->out_dir, mode, lock_fd, err, sizeof(err));
    if (rc == 0 && (rc = scan_dir_sweep(&j->hal->storage, j->out_dir, j->views)) != 0)
        snprintf(err, sizeof(err), "cannot remove the temporary files in %s: %s", j->out_dir,
                 strerror(-rc));
    if (rc != 0) {
        j->hal->log(HAL_LOG_ERROR, "%s", err);
        scan_dir_close(*lock_fd);
        *lock_fd = -1;
    }
    return rc;
}

void job_view_dir(const struct job *j, uint32_t v, char *buf, size_t len)
{
    scan_dir_path(buf, len, j->out_dir, (int)v, NULL);
}

int job_write_failed(const struct job *j, uint32_t v, const char *name, int rc)
{
    char dir[SCAN_DIR_PATH_MAX];
    job_view_dir(j, v, dir, sizeof(dir));
    return job_write_failed_at(j, dir, name, rc);
}

int job_make_view_dir(const struct job *j, uint32_t v)
{
    char dir[SCAN_DIR_PATH_MAX];
    job_view_dir(j, v, dir, sizeof(dir));
    int rc = hal_storage_mkdir_p(&j->hal->storage, dir);
    if (rc != 0)
        j->hal->log(HAL_LOG_ERROR, "cannot make %s: %s", dir, strerror(-rc));
    return rc;
}
