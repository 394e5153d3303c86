/* Scan jobs: the view loop shared by live scans and offline re-processing. */
#define _POSIX_C_SOURCE 200809L
#include "scan_job.h"

#include "board.h"
#include "clock_posix.h"
#include "colour.h"
#include "frame_writer.h"
#include "fusion.h"
#include "gray.h"
#include "reflect.h"
#include "report.h"
#include "scan.h"
#include "scan_dir.h"
#include "thread_posix.h"

#include <errno.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define JOB_MAX_STAGES 8u

struct job {
    const struct hal *hal;
    const struct app_config *cfg;
    const struct scan_calib *calib;
    const struct scan_job_opts *opts;
    const char *out_dir;
    uint32_t views;
    double start_ms;
    double start_cpu_s, start_sim_cpu_s; /* the process's CPU, and the simulator's part of it */
    double start_thread_cpu_s;           /* this (the rig's) thread's CPU */
    double views_cpu_s, last_view_cpu_s; /* the threads that processed views, and the last */
    uint64_t start_rig_us;               /* the rig's clock (the simulator's: the modelled rig's) */
    int tty;
    uint32_t view;                    /* the view being taken or processed */
    char view_dir[SCAN_DIR_PATH_MAX]; /* its directory */
    struct pending *pending;          /* the view processed while the table turns, or NULL */
    struct eta {                      /* views finished of the current run, and when */
        uint32_t first_done, last_done;
        double first_ms, last_ms;
    } eta;
    struct stages { /* when each stage ended (summary.ini), in the order they first did */
        const char *name[JOB_MAX_STAGES];
        double end_s[JOB_MAX_STAGES];
        unsigned n;
    } stages;
};

/* A captured view, processed and saved by a thread of its own while the table turns to the next
 * view (the firmware is used by one thread at a time: the next capture waits for it). */
struct pending {
    struct job *j;
    pthread_t thread;
    uint32_t view;
    char view_dir[SCAN_DIR_PATH_MAX];
    char started[32];
    double t0_ms;
    struct scan_view_info info;
    int rc;
    double cpu_s; /* its thread's CPU */
};

static int load_view(struct job *j, const char *scan_dir, uint32_t v, struct scan_view *view,
                     struct scan_view_info *info);
static int load_range(struct job *j, const char *scan_dir, uint32_t v, struct scan_view *view,
                      struct scan_view_info *info);
static int stopped_offline(struct job *j, const char *scan_dir, uint32_t v);
static int read_into_buffer(const char *scan_dir, uint32_t v, uint32_t f, uint32_t channels,
                            const struct scan_params *params, uint8_t **pixels, char *err,
                            size_t err_len);

static double wall_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

static void job_init(struct job *j, const struct hal *hal, const struct app_config *cfg,
                     const struct scan_calib *calib, const struct scan_job_opts *opts,
                     const char *out_dir)
{
    *j = (struct job){.hal = hal,
                      .cfg = cfg,
                      .calib = calib,
                      .opts = opts,
                      .out_dir = out_dir,
                      .views = cfg->views * cfg->passes, /* every pass's */
                      .start_ms = wall_ms(),
                      .start_cpu_s = clock_posix_process_cpu_s(),
                      .start_sim_cpu_s = board_simulator_cpu_s(),
                      .start_thread_cpu_s = clock_posix_thread_cpu_s(),
                      .tty = isatty(STDOUT_FILENO) && !opts->json};
    if (hal_clock_now_us(&hal->clock, &j->start_rig_us) != 0)
        j->start_rig_us = 0;
}

static void progress(struct job *j, const char *event, int view, uint32_t done, const char *detail);
static void progress_line(struct job *j, const char *event, int view, uint32_t done,
                          const char *fields, const char *detail);
static void progress_with(struct job *j, const char *event, int view, uint32_t done,
                          const char *fields, const char *detail);

/* The CPU the scanner spent since the job began, the simulator's rendering (@p sim_s, out)
 * left out. */
static double own_cpu_s(const struct job *j, double *sim_s)
{
    double cpu = clock_posix_process_cpu_s() - j->start_cpu_s;
    *sim_s = board_simulator_cpu_s() - j->start_sim_cpu_s;
    return cpu - *sim_s;
}

/* The process's peak resident memory: it must not grow with the number of views. */
static double peak_memory_mb(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss / 1024.0;
}

/* What the job cost: the rig's time (with the simulator, the modelled rig's: its turntable and
 * frame rate) and the CPU the scanner spent, the simulator's rendering left out, split by what
 * delays the scan (in line with the rig) and what runs beside it. make bench reads this line. */
static void report_cost(struct job *j, const char *what)
{
    uint64_t now_us = j->start_rig_us;
    hal_clock_now_us(&j->hal->clock, &now_us);
    double sim, own = own_cpu_s(j, &sim);
    uint32_t views = j->views ? j->views : 1;
    char detail[400];
    if (j->views_cpu_s <= 0.0) { /* offline: one thread */
        char fields[96];
        snprintf(detail, sizeof(detail), "%s %.2f s CPU for %u views (%.3f s a view)", what, own,
                 (unsigned)j->views, own / views);
        snprintf(fields, sizeof(fields), "\"cpu_s\":%.3f,\"cpu_per_view_s\":%.4f", own,
                 own / views);
        progress_with(j, "cost", -1, j->views, fields, detail);
        return;
    }
    /* In line with the rig: this thread's work between its moves and captures, and the last
     * view's processing (the others ran while the table turned) */
    double in_line = clock_posix_thread_cpu_s() - j->start_thread_cpu_s - sim + j->last_view_cpu_s;
    int n = snprintf(detail, sizeof(detail),
                     "%s %.2f s CPU for %u views (%.3f s a view: storing frames %.2f s, "
                     "processing views as the table turned %.2f s, in line with the rig %.2f s)",
                     what, own, (unsigned)j->views, own / views, frame_writer_cpu_s(),
                     j->views_cpu_s - j->last_view_cpu_s, in_line);
    double rig_s = (double)(now_us - j->start_rig_us) / 1e6;
    if (sim > 0.0 && n > 0 && (size_t)n < sizeof(detail))
        snprintf(detail + n, sizeof(detail) - (size_t)n,
                 ", the simulator's rendering (%.2f s) left out; %.1f s on the rig's clock", sim,
                 rig_s);
    char fields[256];
    snprintf(fields, sizeof(fields),
             "\"cpu_s\":%.3f,\"cpu_per_view_s\":%.4f,\"storage_cpu_s\":%.3f,"
             "\"in_line_cpu_s\":%.3f,\"simulator_cpu_s\":%.3f,\"rig_s\":%.2f",
             own, own / views, frame_writer_cpu_s(), in_line, sim, rig_s);
    progress_with(j, "cost", -1, j->views, fields, detail);
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

/* @retval 1 for the event that ends a view's line (taken live; fused into the model). */
static int view_finished(const char *event)
{
    return strcmp(event, "saved") == 0 || strcmp(event, "fused") == 0;
}

/* Seconds left of the current run of views (taken live, decoded, or fused after the
 * registration): the measured time a view takes (from the first finished view of the run to the
 * last, so that homing and start-up do not count) times the views left, less the time already
 * spent since the last one finished. -1 until a view's time is known. Only the events that
 * finish a view move it; @p done: views finished of the run. */
static double time_left_s(struct job *j, const char *event, uint32_t done, double now_ms)
{
    struct eta *e = &j->eta;
    int finishes = view_finished(event) || strcmp(event, "decoded") == 0;
    if (finishes && done < e->last_done) /* a new run of views (the fusion after the capture) */
        e->first_done = e->last_done = 0;
    if (finishes && done > e->last_done) {
        if (e->first_done == 0) {
            e->first_done = done;
            e->first_ms = now_ms;
        }
        e->last_done = done;
        e->last_ms = now_ms;
    }
    if (e->last_done >= j->views)
        return 0.0;
    if (e->first_done == 0 || e->last_done == e->first_done)
        return -1.0;
    double per_view_ms = (e->last_ms - e->first_ms) / (e->last_done - e->first_done);
    double left_ms = per_view_ms * (j->views - e->last_done) - (now_ms - e->last_ms);
    return left_ms > 0.0 ? left_ms / 1000.0 : 0.0;
}

/* The stage an event ends, if it ends one: the views taken (live) or decoded (process), then
 * the registration, the reflectance fit, the fusion (which meshing follows), the mesh. */
static void stage_ended(struct job *j, const char *event, double elapsed_s)
{
    static const char *const ends[][2] = {{"saved", "capture"},
                                          {"decoded", "decoding"},
                                          {"registration", "registration"},
                                          {"reflectance", "reflectance fit"},
                                          {"meshing", "fusion"},
                                          {"mesh", "meshing"}};
    struct stages *st = &j->stages;
    for (size_t k = 0; k < sizeof(ends) / sizeof(ends[0]); k++) {
        if (strcmp(event, ends[k][0]) != 0)
            continue;
        unsigned i = 0;
        while (i < st->n && st->name[i] != ends[k][1])
            i++;
        if (i == st->n && st->n < JOB_MAX_STAGES)
            st->name[st->n++] = ends[k][1];
        if (i < st->n)
            st->end_s[i] = elapsed_s;
    }
}

/* One event with its numbers as JSON fields too (@p fields: '"name":value,...' or NULL, for
 * --json). @p view < 0: not about a view. @p done: views finished so far, for the estimate. */
static void progress_with(struct job *j, const char *event, int view, uint32_t done,
                          const char *fields, const char *detail)
{
    /* a line at a time: a view is saved by its own thread while the next is taken */
    static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
    pthread_mutex_lock(&lock);
    progress_line(j, event, view, done, fields, detail);
    pthread_mutex_unlock(&lock);
}

static void progress(struct job *j, const char *event, int view, uint32_t done, const char *detail)
{
    progress_with(j, event, view, done, NULL, detail);
}

static void progress_line(struct job *j, const char *event, int view, uint32_t done,
                          const char *fields, const char *detail)
{
    double now = wall_ms(), elapsed_s = (now - j->start_ms) / 1000.0;
    double left_s = time_left_s(j, event, done, now);
    stage_ended(j, event, elapsed_s);
    if (j->opts->json) {
        printf("{\"event\":\"%s\",\"view\":%d,\"views\":%u,\"views_done\":%u,"
               "\"elapsed_s\":%.1f,\"left_s\":%.1f,%s%s\"detail\":",
               event, view, (unsigned)j->views, (unsigned)done, elapsed_s, left_s,
               fields != NULL ? fields : "", fields != NULL ? "," : "");
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
        if (view_finished(event))
            printf("\n");
    } else if (view >= 0 && view_finished(event)) {
        printf("view %d of %u: %s\n", view + 1, (unsigned)j->views, detail);
    } else if (view < 0) {
        static const char *const human[][2] = {
            {"scan_start", "scanning into"},   {"scan_done", "scan finished:"},
            {"scan_failed", "scan failed:"},   {"process_start", "processing"},
            {"registration", "registration:"}, {"cost", "cost:"},
            {"place_object", ">>>"},           {"process_done", "process finished:"}};
        const char *text = event;
        for (size_t k = 0; k < sizeof(human) / sizeof(human[0]); k++)
            if (strcmp(event, human[k][0]) == 0)
                text = human[k][1];
        printf("%s %s\n", text, detail);
    }
    fflush(stdout);
}

/* Where the results are, and the peak memory. */
static const char *finished_detail(struct job *j, char *buf, size_t len)
{
    snprintf(buf, len, "%s (mesh: %s/mesh.ply, mesh.obj, mesh.stl, mesh.glb; peak memory %.1f MB)",
             j->out_dir, j->out_dir, peak_memory_mb());
    return buf;
}

/* summary.ini (what report.html shows of the job: its stages, time and memory), then
 * report.html. Neither is the scan's result: a failure is said and the job goes on. */
static void write_summary_and_report(struct job *j, const char *command)
{
    char text[1024], path[SCAN_DIR_PATH_MAX], finished[32], err[SCAN_DIR_PATH_MAX + 64];
    utc_now(finished, sizeof(finished));
    double sim, cpu = own_cpu_s(j, &sim);
    int n = snprintf(text, sizeof(text),
                     "; what the %s took, for report.html (docs/scan-format.md)\n[summary]\n"
                     "command = %s\nfinished = %s\nviews = %u\nelapsed_s = %.1f\n"
                     "cpu_s = %.2f\npeak_memory_mb = %.1f\n[stages]\n; seconds from the start "
                     "at which each stage ended\n",
                     command, command, finished, (unsigned)j->views,
                     (wall_ms() - j->start_ms) / 1000.0, cpu, peak_memory_mb());
    for (unsigned i = 0; i < j->stages.n && n > 0 && (size_t)n < sizeof(text); i++)
        n += snprintf(text + n, sizeof(text) - (size_t)n, "%s = %.1f\n", j->stages.name[i],
                      j->stages.end_s[i]);
    int rc = n > 0 && (size_t)n < sizeof(text) ? 0 : -EOVERFLOW;
    if (rc == 0)
        rc = scan_dir_path(path, sizeof(path), j->out_dir, -1, "summary.ini");
    if (rc == 0)
        rc = hal_storage_write_file(&j->hal->storage, path, text, (size_t)n);
    if (rc != 0)
        j->hal->log(HAL_LOG_WARN, "cannot write %s/summary.ini: %s", j->out_dir, strerror(-rc));
    if (report_write(&j->hal->storage, j->out_dir, err, sizeof(err)) != 0)
        j->hal->log(HAL_LOG_WARN, "cannot write the report: %s", err);
}

/* ---- the scan directory ---- */

/* A write into the view's directory that failed, said once, naming the file.
 * @retval @p rc */
static int write_failed_at(const struct job *j, const char *dir, const char *name, int rc)
{
    if (rc != 0)
        j->hal->log(HAL_LOG_ERROR, "cannot write %s/%s: %s", dir, name, strerror(-rc));
    return rc;
}

static int write_failed(const struct job *j, const char *name, int rc)
{
    return write_failed_at(j, j->view_dir, name, rc);
}

/* The directory of the view being processed, in the output directory. @retval 0 @retval -errno
 * (said) */
static int make_view_dir(const struct job *j)
{
    int rc = hal_storage_mkdir_p(&j->hal->storage, j->view_dir);
    if (rc != 0)
        j->hal->log(HAL_LOG_ERROR, "cannot make %s: %s", j->view_dir, strerror(-rc));
    return rc;
}

/* Frames a scan keeps ([output] keep_frames): "colour" keeps the white pattern (the colour of
 * method none, the white of the others), the light frames and an HDR scan's colour frame. */
static int keeps_frame(const struct job *j, uint32_t frame)
{
    if (j->cfg->keep_frames != KEEP_FRAMES_COLOUR)
        return j->cfg->keep_frames == KEEP_FRAMES_ALL;
    return scan_frame_channels(&j->cfg->scan, j->calib, frame) == 3;
}

/* A frame goes to the storage thread; a write of an earlier frame that failed is said here,
 * once, with its file. */
static int save_frame(void *priv, uint32_t pattern, const uint8_t *pixels, uint32_t width,
                      uint32_t height, uint32_t channels)
{
    struct job *j = priv;
    char failed[SCAN_DIR_PATH_MAX] = "";
    if (!keeps_frame(j, pattern))
        return 0;
    int rc = frame_writer_put(j->out_dir, j->view, pattern, pixels, width, height, channels,
                              (enum scan_frame_format)j->cfg->frame_format, failed, sizeof(failed));
    if (rc != 0)
        j->hal->log(HAL_LOG_ERROR, "cannot write %s: %s", failed[0] ? failed : j->view_dir,
                    strerror(-rc));
    return rc;
}

/* Every frame of the view on disk (before its view.ini); a failed write said once. */
static int flush_frames(const struct job *j)
{
    char failed[SCAN_DIR_PATH_MAX] = "";
    int rc = frame_writer_flush(failed, sizeof(failed));
    if (rc != 0)
        j->hal->log(HAL_LOG_ERROR, "cannot write %s: %s", failed, strerror(-rc));
    return rc;
}

void scan_job_view_meta(const struct app_config *cfg, const struct scan_params *params,
                        const struct scan_calib *calib, uint32_t view,
                        const struct scan_view_info *info, struct scan_dir_view *v)
{
    memset(v, 0, sizeof(*v));
    v->index = view;
    v->angle_mdeg = info->angle_mdeg;
    v->frames = info->frames_captured;
    v->capture_retries = info->capture_retries;
    v->valid_points = info->valid_points;
    v->exposure_us = cfg->camera.exposure_us;
    v->gain_milli = cfg->camera.gain_milli;
    scan_dir_describe_frames(params, calib, v);
    memcpy(v->reason_count, info->reason_count, sizeof(v->reason_count));
}

static int write_view_meta(const struct pending *p, double ms)
{
    static struct scan_dir_view v; /* large; one view at a time */
    const struct job *j = p->j;
    scan_job_view_meta(j->cfg, &j->cfg->scan, j->calib, p->view, &p->info, &v);
    snprintf(v.started, sizeof(v.started), "%s", p->started);
    utc_now(v.finished, sizeof(v.finished));
    v.wall_ms = ms;
    return write_failed_at(j, p->view_dir, "view.ini",
                           scan_dir_write_view(&j->hal->storage, j->out_dir, p->view, &v));
}

/* Results of a processed view once the scan is registered: its registration.ini, its point
 * cloud and its part of the fused model, all at the registered pose. @p rv: out, the view's
 * part of the registration. */
static int save_results(struct job *j, const struct scan_view *view, const struct reg_report *rep,
                        struct reg_view *rv)
{
    char path[HAL_MAX_PATH + 64];
    struct frame_xform pose;
    int rc = reg_view_pose(j->view, &pose, rv);
    if (rc == 0)
        rc = write_failed(
            j, "registration.ini",
            scan_dir_write_registration(&j->hal->storage, j->out_dir, j->view, rep, rv, &pose));
    if (rc == 0)
        rc = scan_dir_path(path, sizeof(path), j->out_dir, (int)j->view, "cloud.ply");
    if (rc == 0)
        rc = scan_save_cloud(j->hal, view, &pose, path); /* says what failed itself */
    if (rc == 0)
        rc = scan_fuse_view(j->calib, view, &pose);
    return rc;
}

static void describe(char *buf, size_t len, const struct scan_view_info *info, const char *dir)
{
    snprintf(buf, len, "%u points at %.1f deg -> %s", (unsigned)info->valid_points,
             info->angle_mdeg / 1000.0, dir);
}

static void set_view(struct job *j, uint32_t view)
{
    j->view = view;
    scan_dir_path(j->view_dir, sizeof(j->view_dir), j->out_dir, (int)view, NULL);
}

/* The fused model: mesh.ply, mesh.obj, mesh.stl and mesh.glb in the scan directory, without
 * floating fragments. */
static int write_model(struct job *j)
{
    static const char *const names[] = {"mesh.ply", "mesh.obj", "mesh.stl", "mesh.glb"};
    int (*const writers[])(const struct hal_storage *, const char *) = {
        fusion_write_ply, fusion_write_obj, fusion_write_stl, fusion_write_glb};
    char path[SCAN_DIR_PATH_MAX], detail[HAL_MAX_PATH + 320];
    struct mesh_summary ms;
    uint32_t filled = 0, inside = 0;
    progress(j, "meshing", -1, j->views, "marching cubes");
    int rc = fusion_fill_holes(j->cfg->max_hole_mm, &filled);
    if (rc == 0 && j->cfg->watertight)
        rc = fusion_close_watertight(j->cfg->max_hole_mm, j->cfg->passes == 1, &inside);
    if (rc == 0)
        rc = fusion_mesh_prepare(j->cfg->min_fragment_share, &ms);
    int fits = rc == 0;
    if (rc == -E2BIG)
        j->hal->log(HAL_LOG_WARN,
                    "the mesh has %u vertices, more than MESH_MAX_VERTICES (%u): it is written "
                    "whole, fragments and all, and without mesh.stl and mesh.glb (a larger "
                    "[fusion] voxel_mm "
                    "makes a smaller mesh)",
                    (unsigned)ms.vertices, MESH_MAX_VERTICES);
    else if (rc != 0)
        return rc;
    rc = 0;
    for (size_t k = 0; k < sizeof(names) / sizeof(names[0]) && rc == 0; k++) {
        if (!fits && (writers[k] == fusion_write_stl || writers[k] == fusion_write_glb))
            continue;
        rc = scan_dir_path(path, sizeof(path), j->out_dir, -1, names[k]);
        if (rc == 0 && (rc = writers[k](&j->hal->storage, path)) != 0)
            j->hal->log(HAL_LOG_ERROR, "cannot write %s: %s", path, strerror(-rc));
    }
    if (rc != 0)
        return rc;
    char closed[96] = "";
    if (j->cfg->watertight)
        snprintf(closed, sizeof(closed), ", closed watertight, %u unseen voxels made solid",
                 (unsigned)inside);
    char uncoloured[128] = "";
    if (ms.colour_filled > 0 || ms.uncoloured > 0)
        snprintf(uncoloured, sizeof(uncoloured),
                 "; %u vertices no view could colour took their neighbours' colour, %u marked "
                 "grey",
                 (unsigned)ms.colour_filled, (unsigned)ms.uncoloured);
    snprintf(detail, sizeof(detail),
             "%u vertices, %u triangles (%u floating fragments of %u pieces left out; %u voxels "
             "filled holes%s%s) -> %s/mesh.ply, mesh.obj%s",
             (unsigned)ms.kept_vertices, (unsigned)ms.kept_triangles, (unsigned)ms.removed_pieces,
             (unsigned)ms.pieces, (unsigned)filled, closed, uncoloured, j->out_dir,
             fits ? ", mesh.stl and mesh.glb" : "");
    char fields[192];
    snprintf(fields, sizeof(fields),
             "\"vertices\":%u,\"triangles\":%u,\"pieces_left_out\":%u,\"colour_filled\":%u,"
             "\"uncoloured\":%u",
             (unsigned)ms.kept_vertices, (unsigned)ms.kept_triangles, (unsigned)ms.removed_pieces,
             (unsigned)ms.colour_filled, (unsigned)ms.uncoloured);
    progress_with(j, "mesh", -1, j->views, fields, detail);
    return 0;
}

/* Before the first view: the registration sized for the scan's views. */
static int begin_model(struct job *j)
{
    int rc = reg_begin(&j->cfg->registration, j->calib, j->views, j->cfg->passes,
                       j->cfg->scan.width, j->cfg->scan.height);
    if (rc != 0)
        j->hal->log(HAL_LOG_ERROR, "registration: %u views exceed the compiled limit %u",
                    (unsigned)j->views, REG_MAX_VIEWS);
    return rc;
}

/* The registration's one quality line, and a refused or failed one said plainly. */
static int report_registration(struct job *j, const struct reg_report *r, double cpu_seconds,
                               const char *scan_dir)
{
    char detail[512];
    if (!r->solved)
        snprintf(detail, sizeof(detail),
                 "turntable angles kept ([registration] icp = 0 or one "
                 "view)");
    else
        snprintf(detail, sizeof(detail),
                 "residual %.3f mm, loop closure %.3f mm, worst view %u (%.3f mm); axis moved "
                 "%.2f mm, tilted %.3f deg; %.2f s CPU; %s%s",
                 r->rms_mm, r->loop_rms_mm, (unsigned)r->worst_view, r->worst_rms_mm,
                 r->axis_shift_mm, r->axis_tilt_deg, cpu_seconds,
                 r->accepted ? "the views' angles corrected" : "turntable angles kept: ",
                 r->accepted ? "" : r->refused);
    if (j->cfg->passes == 2 && r->failed_view < 0) {
        size_t n = strlen(detail);
        snprintf(detail + n, sizeof(detail) - n,
                 "; second pass found turned %.1f deg, residual %.3f mm over %u pairs",
                 r->second_turned_deg, r->second_rms_mm, (unsigned)r->second_coupled);
    }
    char fields[160];
    snprintf(fields, sizeof(fields),
             "\"solved\":%d,\"accepted\":%d,\"residual_mm\":%.4f,\"loop_closure_mm\":%.4f,"
             "\"cpu_s\":%.3f",
             r->solved, r->accepted, r->rms_mm, r->loop_rms_mm, cpu_seconds);
    progress_with(j, "registration", -1, j->views, fields, detail);
    if (r->failed_view >= 0 && r->failed_against < 0) {
        j->hal->log(HAL_LOG_ERROR,
                    "registration failed: the second pass (from view %d) matches nothing of the "
                    "first (%.0f%% of its points paired, at least %.0f%% needed): was it the same "
                    "object? No model was made; the views are kept in %s",
                    r->failed_view, 100.0 * r->failed_share,
                    100.0 * j->cfg->registration.min_coupled_share, scan_dir);
        return -EPROTO;
    }
    if (!r->solved || r->failed_view < 0)
        return 0;
    j->hal->log(HAL_LOG_ERROR,
                "registration failed: view %d does not match view %d (%.0f%% of their overlap "
                "couples, at least %.0f%% needed): did the object move on the table? No model "
                "was made; the views are kept in %s. Scan again, or fuse them at the turntable's "
                "angles with 'scanner process %s --config F' where F has [registration] icp = 0",
                r->failed_view, r->failed_against, 100.0 * r->failed_share,
                100.0 * j->cfg->registration.min_coupled_share, scan_dir, scan_dir);
    return -EPROTO;
}

/* [colour] method = fit: view @p v's colour frames read back from @p scan_dir into the
 * firmware's buffers (range.bin keeps the view's colour, not its frames), and its colour made
 * again with them: while the pool collects, the multi estimate and samples; once the lobes are
 * fitted, the diffuse colour under them. */
static int recolour_from_frames(struct job *j, const char *scan_dir, uint32_t v,
                                struct scan_view *view)
{
    const struct scan_params *p = &j->cfg->scan;
    struct gray_layout layout;
    scan_layout(p, j->calib, &layout);
    uint32_t count = gray_layout_count(&layout), lights = scan_light_frame_count(p, j->calib);
    uint32_t white = p->exposure_count > 0 ? count + lights : GRAY_PATTERN_WHITE;
    char err[SCAN_DIR_PATH_MAX + 256];
    int rc = scan_begin_view(p, j->calib);
    for (uint32_t f = count; rc == 0 && f <= count + lights; f++) {
        uint32_t frame = f < count + lights ? f : white; /* the lights, then the white colour */
        uint8_t *pixels;
        rc = read_into_buffer(scan_dir, v, frame, 3, p, &pixels, err, sizeof(err));
        if (rc == 0 && f < count + lights)
            rc = scan_feed_light_frame(f - count, pixels);
    }
    if (rc != 0) {
        j->hal->log(HAL_LOG_ERROR, "[colour] method = fit needs the colour frames: %s", err);
        return rc;
    }
    scan_attach_colour(view);
    return scan_recolour(&p->colour, j->calib, view);
}

/* View @p v as the model is made of it (load_range), coloured again from its frames while the
 * reflectance pool collects or once its model is fitted (fit); stopped by request between
 * views. */
static int view_for_model(struct job *j, const char *scan_dir, uint32_t v, struct scan_view *view,
                          struct scan_view_info *info)
{
    int rc = stopped_offline(j, scan_dir, v);
    if (rc == 0)
        rc = load_range(j, scan_dir, v, view, info);
    if (rc == 0 && (reflect_collecting() || reflect_model() != NULL))
        rc = recolour_from_frames(j, scan_dir, v, view);
    return rc;
}

/* [colour] method = fit: the samples of every view (each view's colour frames read back), the
 * clusters and their lobes fitted, said and kept in reflectance.ini. Too few samples: the views
 * keep the multi estimate, said. */
static int fit_reflectance(struct job *j, const char *scan_dir)
{
    reflect_forget();
    if (j->cfg->scan.colour.method != COLOUR_FIT)
        return 0;
    double t0 = clock_posix_thread_cpu_s();
    reflect_begin(j->views);
    int rc = 0;
    for (uint32_t v = 0; v < j->views && rc == 0; v++) {
        struct scan_view view;
        struct scan_view_info info;
        rc = view_for_model(j, scan_dir, v, &view, &info);
    }
    struct reflect_model m;
    if (rc == 0 && (rc = reflect_fit(j->cfg->scan.colour.clusters, &m)) == -ENODATA) {
        j->hal->log(HAL_LOG_WARN, "reflectance: too few samples to fit (lit, unsaturated "
                                  "surface seen by two lights or more); the views keep the "
                                  "multi method's colour");
        return 0;
    }
    if (rc == 0)
        rc = write_failed(j, "reflectance.ini",
                          scan_dir_write_reflectance(&j->hal->storage, j->out_dir, &m));
    if (rc != 0)
        return rc;
    char detail[128 + REFLECT_MAX_CLUSTERS * 96];
    size_t len = (size_t)snprintf(detail, sizeof(detail),
                                  "%u material clusters (%.2f s CPU):", (unsigned)m.count,
                                  clock_posix_thread_cpu_s() - t0);
    for (uint32_t k = 0; k < m.count && len < sizeof(detail); k++) {
        const struct reflect_cluster *c = &m.cluster[k];
        len +=
            (size_t)snprintf(detail + len, sizeof(detail) - len,
                             "%s diffuse %.2f %.2f %.2f, specular %.3f %.3f %.3f, roughness "
                             "%.3f (%u samples)",
                             k ? ";" : "", c->centre[0], c->centre[1], c->centre[2], c->specular[0],
                             c->specular[1], c->specular[2], c->roughness, (unsigned)c->samples);
    }
    char fields[64];
    snprintf(fields, sizeof(fields), "\"clusters\":%u", (unsigned)m.count);
    progress_with(j, "reflectance", -1, j->views, fields, detail);
    return 0;
}

/* Once every view is in: register them jointly, then fuse each at its registered pose. The
 * fusion must wait for the registration, and the views' range images are not kept in memory
 * (a view's are 40 MB): each is read back from its range.bin in the output directory, or, for a
 * scan kept before range.bin existed, decoded again from its frames in @p scan_dir. */
static int make_model(struct job *j, const char *scan_dir)
{
    struct reg_report rep;
    double t0 = clock_posix_thread_cpu_s();
    reg_solve(&rep);
    int rc = report_registration(j, &rep, clock_posix_thread_cpu_s() - t0, scan_dir);
    if (rc == 0)
        rc = fit_reflectance(j, scan_dir);
    if (rc == 0)
        rc = fusion_begin(&j->cfg->fusion);
    for (uint32_t v = 0; v < j->views && rc == 0; v++) {
        struct scan_view view;
        struct scan_view_info info;
        rc = view_for_model(j, scan_dir, v, &view, &info);
        if (rc == 0)
            rc = make_view_dir(j);
        struct reg_view rv;
        if (rc == 0)
            rc = save_results(j, &view, &rep, &rv);
        if (rc == 0) {
            char detail[HAL_MAX_PATH + 160];
            char fields[96];
            snprintf(detail, sizeof(detail), "fused at %.3f deg (%+.3f deg from the table's) -> %s",
                     rv.angle_deg, rv.correction_deg, j->view_dir);
            snprintf(fields, sizeof(fields), "\"angle_deg\":%.4f,\"correction_deg\":%.4f",
                     rv.angle_deg, rv.correction_deg);
            progress_with(j, "fused", (int)v, v + 1, fields, detail);
        }
    }
    return rc == 0 ? write_model(j) : rc;
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

/* The table did not get to view @p v. The turntable client has said why (the error, once);
 * this says what is kept and how to go on, which depends on whether an alarm blocks the table. */
static void table_failed(const struct job *j, uint32_t v, int32_t target_mdeg)
{
    const struct hal *hal = j->hal;
    struct hal_turntable_status st;
    char kept[2 * HAL_MAX_PATH + 96];
    if (hal_table_get_status(&hal->turntable, &st) == 0 && st.alarm_code != 0)
        hal->log(HAL_LOG_WARN,
                 "view %u was not taken at %.3f deg: the table stopped at %.3f deg with alarm %u; "
                 "once it turns freely, %s",
                 (unsigned)v, target_mdeg / 1000.0, st.position_mdeg / 1000.0,
                 (unsigned)st.alarm_code, kept_views(j, v, " --clear-alarm", kept, sizeof(kept)));
    else
        hal->log(HAL_LOG_WARN, "view %u was not taken at %.3f deg; %s", (unsigned)v,
                 target_mdeg / 1000.0, kept_views(j, v, "", kept, sizeof(kept)));
}

/* A view that will not be complete: said once, with what is kept and how to go on. */
static void view_not_finished(const struct job *j, uint32_t v, int32_t angle_mdeg, int rc)
{
    char kept[2 * HAL_MAX_PATH + 96];
    j->hal->log(HAL_LOG_WARN, "view %u at %.3f deg was not finished (%s); %s", (unsigned)v,
                angle_mdeg / 1000.0, rc == -EINTR ? "stopped by request" : strerror(-rc),
                kept_views(j, v, "", kept, sizeof(kept)));
}

/* Decode a captured view, keep its frames and range image, then its view.ini last (its
 * presence says the view is complete). @retval 0 @retval -errno (said) */
static int save_view(struct pending *p)
{
    struct job *j = p->j;
    const struct hal *hal = j->hal;
    struct scan_view view;
    char detail[HAL_MAX_PATH + 160], fields[96];
    int rc = scan_finish_view(j->calib, p->info.angle_mdeg, &view, &p->info);
    int rc_frames = flush_frames(j); /* nothing writes into the view's directory after this */
    if (rc == 0)
        rc = rc_frames;
    if (rc != 0) { /* the layer that met the fault has said what it was */
        view_not_finished(j, p->view, p->info.angle_mdeg, rc);
        return rc;
    }
    progress(j, "saving", (int)p->view, p->view, "");
    rc = scan_keep_for_registration(p->view, &view); /* the model is made once every view is in */
    if (rc == 0) /* what the model is made of, so that it is not decoded again */
        rc = write_failed_at(j, p->view_dir, "range.bin",
                             scan_dir_write_range(&hal->storage, j->out_dir, p->view, &view));
    if (rc == 0)
        rc = write_view_meta(p, wall_ms() - p->t0_ms);
    if (rc != 0)
        return rc;
    describe(detail, sizeof(detail), &p->info, p->view_dir);
    snprintf(fields, sizeof(fields), "\"points\":%u,\"angle_deg\":%.3f",
             (unsigned)p->info.valid_points, p->info.angle_mdeg / 1000.0);
    progress_with(j, "saved", (int)p->view, p->view + 1, fields, detail);
    return 0;
}

/* The thread of a captured view: save_view, its result and CPU kept for finish_pending. */
static void *process_view(void *arg)
{
    struct pending *p = arg;
    double t0 = clock_posix_thread_cpu_s();
    p->rc = save_view(p);
    p->cpu_s = clock_posix_thread_cpu_s() - t0;
    return NULL;
}

/* The view processed: its result, its CPU counted. @retval its error (said already) */
static int view_processed(struct job *j, const struct pending *p)
{
    j->views_cpu_s += p->cpu_s;
    j->last_view_cpu_s = p->cpu_s;
    return p->rc;
}

/* Wait for the view being processed, if any. @retval 0 @retval its error (said already) */
static int finish_pending(struct job *j)
{
    if (j->pending == NULL)
        return 0;
    pthread_join(j->pending->thread, NULL);
    int rc = view_processed(j, j->pending);
    j->pending = NULL;
    return rc;
}

/* Process the view just captured on a thread of its own, so that the table turns meanwhile;
 * without a thread, here. @retval 0 @retval what processing it met */
static int start_processing(struct job *j, uint32_t v, const char *started, double t0_ms,
                            const struct scan_view_info *info)
{
    static struct pending p; /* one at a time */
    p = (struct pending){.j = j, .view = v, .t0_ms = t0_ms, .info = *info};
    snprintf(p.view_dir, sizeof(p.view_dir), "%s", j->view_dir);
    snprintf(p.started, sizeof(p.started), "%s", started);
    int rc = thread_posix_start(&p.thread, 0, process_view, &p);
    if (rc == 0) {
        j->pending = &p;
        return 0;
    }
    j->hal->log(HAL_LOG_WARN,
                "cannot start a thread (%s): view %u is processed before the "
                "table turns",
                strerror(-rc), (unsigned)v);
    process_view(&p);
    return view_processed(j, &p);
}

static int live_view(struct job *j, uint32_t v)
{
    const struct hal *hal = j->hal;
    uint32_t k = v % j->cfg->views; /* the view's place in its pass */
    int32_t target = (int32_t)((j->cfg->start_angle_deg + 360.0 * k / j->cfg->views) * 1000.0);
    char detail[HAL_MAX_PATH + 160], started[32];
    snprintf(detail, sizeof(detail), "to %.1f deg", target / 1000.0);
    progress(j, "moving", (int)v, v, detail);
    int rc = hal_table_move_to(&hal->turntable, target);
    struct hal_turntable_status st;
    if (rc == 0)
        rc = hal_table_get_status(&hal->turntable, &st); /* the angle the controller reports */
    int rc_before = finish_pending(j); /* the view before, processed while the table turned */
    if (rc_before != 0)
        return rc_before;
    if (rc != 0) {
        table_failed(j, v, target);
        return rc;
    }
    set_view(j, v);
    rc = scan_dir_begin_view(&hal->storage, j->out_dir, v); /* no view.ini of an earlier take */
    if (rc != 0) {
        hal->log(HAL_LOG_ERROR, "cannot prepare %s: %s", j->view_dir, strerror(-rc));
        return rc;
    }
    utc_now(started, sizeof(started));
    progress(j, "capturing", (int)v, v, "");
    struct scan_frame_sink sink = {save_frame, j};
    struct scan_view_info info;
    double t0 = wall_ms();
    rc = scan_capture_view(hal, &j->cfg->scan, j->calib, st.position_mdeg, &sink, &info);
    /* the simulator's truth of this view while the table is still at its angle */
    if (rc == 0)
        rc = write_failed(j, "(the simulator's truth)", board_write_view_extras(hal, j->view_dir));
    if (rc != 0) {       /* the layer that met the fault has said what it was */
        flush_frames(j); /* nothing writes into the view's directory after this */
        view_not_finished(j, v, st.position_mdeg, rc);
        return rc;
    }
    return start_processing(j, v, started, t0, &info);
}

/* The person lays the object for the second pass (the simulated person does it at once).
 * @retval 0 @retval -EINTR the person stopped (Ctrl-D) @retval -errno */
static int ask_for_second_pass(struct job *j)
{
    char err[256];
    const char *detail = "pass 2 of 2: lay the object on its side (another way than before), "
                         "near the middle of the table";
    struct board_target t = {.kind = BOARD_TARGET_OBJECT, .pass = 2};
    progress(j, "place_object", -1, 0, detail);
    int rc = board_place_target((struct hal *)j->hal, &t, err, sizeof(err));
    if (rc == 0)
        return 0;
    if (rc != -ENOSYS) {
        j->hal->log(HAL_LOG_ERROR, "%s", err);
        return rc;
    }
    printf("%s; press Enter when it is done (Ctrl-D stops; the views so far are kept).\n", detail);
    fflush(stdout);
    char line[64];
    return fgets(line, sizeof(line), stdin) == NULL || hal_should_stop(j->hal) ? -EINTR : 0;
}

/* The storage thread that keeps the frames while the next are taken. */
static int start_storage(const struct job *j)
{
    int rc = frame_writer_start(&j->hal->storage);
    if (rc != 0)
        j->hal->log(HAL_LOG_ERROR, "cannot start the storage thread: %s", strerror(-rc));
    return rc;
}

/* Home the table, then take views @p first .. the last, each processed and saved while the
 * table turns to the next; a two-pass scan asks for the object to be laid for the second pass
 * (the first pass saved), and homes again. */
static int home_and_take_views(struct job *j, uint32_t first)
{
    const struct hal *hal = j->hal;
    int rc = 0;
    if (j->cfg->passes == 2 && first >= j->cfg->views) /* resumed in the second pass */
        rc = ask_for_second_pass(j);
    if (rc == 0)
        progress(j, "homing", (int)first, first, "");
    if (rc == 0 && j->opts->clear_alarm && (rc = hal_table_clear_alarm(&hal->turntable)) == -ENOSYS)
        hal->log(HAL_LOG_ERROR, "this turntable cannot clear its alarm over its link: clear it "
                                "at the controller, then resume without --clear-alarm");
    if (rc == 0 && (rc = hal_table_home(&hal->turntable)) != 0) /* the client said why */
        hal->log(HAL_LOG_WARN, "the turntable did not home%s",
                 j->opts->clear_alarm ? "" : " (if it reports an alarm: --clear-alarm)");
    for (uint32_t v = first; v < j->views && rc == 0; v++) {
        if (v == j->cfg->views && v != first) { /* the second pass begins */
            rc = finish_pending(j);
            if (rc == 0)
                rc = ask_for_second_pass(j);
            if (rc == 0 && (rc = hal_table_home(&hal->turntable)) != 0)
                hal->log(HAL_LOG_WARN, "the turntable did not home for the second pass");
        }
        if (rc == 0)
            rc = live_view(j, v);
    }
    int rc_last = finish_pending(j); /* on every path: a captured view is always saved */
    return rc != 0 ? rc : rc_last;
}

/* Lock the job's output directory against a second scanner (checking what it holds by
 * @p mode) and sweep what a kill left there; a refusal is said once. */
static int open_out(struct job *j, enum scan_dir_mode mode, int *lock_fd)
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

/* A scan without --out goes to a new folder under [output] dir named by when it began (UTC),
 * so that no scan ever replaces another. @retval 0 @retval -EEXIST (a hundred this second) */
static int new_scan_dir(const char *parent, char *out, size_t len, const char **name)
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
        if (access(out, F_OK) != 0) {
            *name = out + strlen(parent) + 1;
            return 0;
        }
    }
    return -EEXIST;
}

/* [output] dir/latest: a link to the newest scan's folder, replaced atomically. A convenience:
 * a failure is said and the scan goes on. */
static void link_latest(const struct hal *hal, const char *parent, const char *name)
{
    char link[HAL_MAX_PATH + 16], temp[HAL_MAX_PATH + 32];
    snprintf(link, sizeof(link), "%s/latest", parent);
    snprintf(temp, sizeof(temp), "%s/.latest.%ld", parent, (long)getpid());
    unlink(temp);
    if (symlink(name, temp) != 0 || rename(temp, link) != 0) {
        hal->log(HAL_LOG_WARN, "cannot point %s at %s: %s", link, name, strerror(errno));
        unlink(temp);
    }
}

int scan_job_live(const struct hal *hal, const struct app_config *cfg,
                  const struct scan_calib *calib, const struct scan_job_opts *opts)
{
    static char auto_dir[HAL_MAX_PATH + 32];
    const char *name = NULL;
    if (opts->out_dir == NULL) {
        int rc = new_scan_dir(cfg->output_dir, auto_dir, sizeof(auto_dir), &name);
        if (rc != 0) {
            hal->log(HAL_LOG_ERROR, "cannot name a new scan folder in %s: %s", cfg->output_dir,
                     strerror(-rc));
            return rc;
        }
    }
    struct job j;
    job_init(&j, hal, cfg, calib, opts, opts->out_dir ? opts->out_dir : auto_dir);
    char path[HAL_MAX_PATH + 32];
    int lock_fd;
    int rc = open_out(&j, opts->replace ? SCAN_DIR_REPLACE : SCAN_DIR_NEW, &lock_fd);
    if (rc != 0)
        return rc;
    if (name != NULL)
        link_latest(hal, cfg->output_dir, name);
    rc = scan_dir_keep_settings(&hal->storage, cfg->path, cfg->calibration_file, j.out_dir);
    if (rc != 0) {
        hal->log(HAL_LOG_ERROR, "cannot set up the scan directory %s: %s", j.out_dir,
                 strerror(-rc));
        goto out_unlock;
    }
    rc = begin_model(&j);
    if (rc == 0)
        rc = write_failed(&j, "(the simulator's truth)", board_write_scan_extras(hal, j.out_dir));
    if (rc != 0)
        goto out_unlock;
    progress(&j, "scan_start", -1, 0, j.out_dir);
    rc = start_storage(&j);
    if (rc == 0)
        rc = home_and_take_views(&j, 0);
    frame_writer_stop();
    if (rc == 0)
        rc = make_model(&j, j.out_dir);
    if (rc == 0)
        report_cost(&j, "the scan");
    if (rc == 0)
        write_summary_and_report(&j, "scan");
    if (rc == 0)
        progress(&j, "scan_done", -1, j.views, finished_detail(&j, path, sizeof(path)));
    else if (opts->json)
        progress(&j, "scan_failed", -1, 0, strerror(-rc));
out_unlock:
    scan_dir_close(lock_fd);
    return rc;
}

/* ---- resume ---- */

int scan_job_load_settings(const char *scan_dir, const char *config_path, struct app_config *cfg,
                           struct scan_calib *calib, char *err, size_t err_len)
{
    char path[SCAN_DIR_PATH_MAX];
    int rc = scan_dir_path(path, sizeof(path), scan_dir, -1, "config.ini");
    if (rc == 0 && config_path == NULL && access(path, F_OK) != 0) {
        snprintf(err, err_len,
                 "%s holds no scan (no config.ini; a scan stopped before its first file has "
                 "nothing to go on with: take it again with 'scanner scan --config F --out %s "
                 "--replace')",
                 scan_dir, scan_dir);
        return -ENOENT;
    }
    if (rc == 0)
        rc = config_load(cfg, config_path ? config_path : path, err, err_len);
    /* other settings: the colour frames are those the scan took (method none shows the raw
     * colour of a scan taken with every light) */
    static struct app_config taken;
    if (rc == 0 && config_path != NULL && access(path, F_OK) == 0 &&
        config_load(&taken, path, err, err_len) == 0)
        cfg->scan.colour.taken_with = taken.scan.colour.method;
    /* the calibration is the copy kept with the scan, whatever the config named */
    if (rc == 0)
        rc = scan_dir_path(cfg->calibration_file, sizeof(cfg->calibration_file), scan_dir, -1,
                           "calibration.ini");
    return rc != 0 ? rc : calib_load(calib, cfg->calibration_file, cfg->light_count, err, err_len);
}

int scan_job_resume(const struct hal *hal, const struct app_config *cfg,
                    const struct scan_calib *calib, const char *scan_dir,
                    const struct scan_job_opts *opts)
{
    struct job j;
    job_init(&j, hal, cfg, calib, opts, scan_dir);
    char detail[64];
    int lock_fd;
    int rc = open_out(&j, SCAN_DIR_EXISTING, &lock_fd);
    if (rc != 0)
        return rc;
    uint32_t first = 0;
    while (first < j.views && scan_dir_view_complete(scan_dir, first))
        first++;
    snprintf(detail, sizeof(detail), "%u of %u views kept", (unsigned)first, (unsigned)j.views);
    progress(&j, "resume", -1, first, detail);
    if (first < j.views) {
        rc = begin_model(&j); /* the model comes from scan_job_process afterwards */
        if (rc == 0)
            rc = start_storage(&j);
        if (rc == 0)
            rc = home_and_take_views(&j, first);
        frame_writer_stop();
    }
    scan_dir_close(lock_fd);
    return rc;
}

/* ---- offline ---- */

/* The frames the settings need must be the frames the view holds: a config with another
 * exposure or another number of lights would feed the wrong frame to each step. */
static int check_frames(const struct job *j, const char *scan_dir, uint32_t v,
                        const struct scan_dir_view *have, char *err, size_t err_len)
{
    static struct scan_dir_view want;
    scan_dir_describe_frames(&j->cfg->scan, j->calib, &want);
    for (uint32_t f = 0; f < want.frame_count; f++) {
        if (f < have->frame_count && strcmp(have->frame_name[f], want.frame_name[f]) == 0)
            continue;
        snprintf(err, err_len,
                 "%s/view_%03u/view.ini: frame_%02u is '%s', but these settings need '%s' "
                 "there (other [scan] or [colour] settings than the scan was taken with?)",
                 scan_dir, (unsigned)v, (unsigned)f,
                 f < have->frame_count ? have->frame_name[f] : "(none)", want.frame_name[f]);
        return -EINVAL;
    }
    return 0;
}

/* Frame @p f of view @p v read from @p scan_dir straight into the firmware's buffer for it (fed
 * without a copy), as @p channels channels. @p pixels: out, that buffer. @retval 0
 * @retval -EINVAL no buffer for it (@p err says) @retval as scan_dir_read_frame */
static int read_into_buffer(const char *scan_dir, uint32_t v, uint32_t f, uint32_t channels,
                            const struct scan_params *params, uint8_t **pixels, char *err,
                            size_t err_len)
{
    *pixels = scan_frame_buffer(f);
    if (*pixels == NULL) {
        snprintf(err, err_len, "view %u: frame %u has no buffer in these settings", (unsigned)v,
                 (unsigned)f);
        return -EINVAL;
    }
    return scan_dir_read_frame(scan_dir, v, f, *pixels, (size_t)HAL_MAX_PIXELS * channels,
                               params->width, params->height, channels, err, err_len);
}

int scan_job_feed_view(const char *scan_dir, uint32_t v, const struct scan_params *params,
                       const struct scan_calib *calib, char *err, size_t err_len)
{
    struct gray_layout layout;
    scan_layout(params, calib, &layout);
    uint32_t count = gray_layout_count(&layout);
    uint32_t lights = scan_light_frame_count(params, calib);
    uint32_t channels;
    int rc = scan_begin_view(params, calib);
    for (uint32_t f = 0; rc == 0 && (channels = scan_frame_channels(params, calib, f)) != 0; f++) {
        uint8_t *pixels;
        rc = read_into_buffer(scan_dir, v, f, channels, params, &pixels, err, err_len);
        if (rc == 0)
            rc = f < count            ? scan_feed_frame(f, pixels, channels, NULL)
                 : f < count + lights ? scan_feed_light_frame(f - count, pixels)
                                      : scan_feed_white_colour(pixels);
    }
    return rc;
}

/* View @p v read back from its range.bin in @p dir, with what describe() says of it (the
 * reader has checked that the valid pixels are the header's count). @retval 0 @retval -ENOENT
 * none @retval -EINVAL (@p err says) */
static int read_range(struct job *j, const char *dir, uint32_t v, struct scan_view *view,
                      struct scan_view_info *info, char *err, size_t err_len)
{
    set_view(j, v);
    int rc =
        scan_dir_read_range(dir, v, j->cfg->scan.width, j->cfg->scan.height, view, err, err_len);
    if (rc == 0) {
        memset(info, 0, sizeof(*info));
        info->angle_mdeg = view->angle_mdeg;
        info->valid_points = view->range.valid_count;
    }
    return rc;
}

/* View @p v of a scan that kept no pattern frames: its range.bin in @p scan_dir. */
static int load_kept_range(struct job *j, const char *scan_dir, uint32_t v, struct scan_view *view,
                           struct scan_view_info *info)
{
    char err[SCAN_DIR_PATH_MAX + 128];
    int rc = read_range(j, scan_dir, v, view, info, err, sizeof(err));
    if (rc != 0)
        j->hal->log(HAL_LOG_ERROR, "%s; the scan kept no pattern frames to decode it from", err);
    return rc;
}

/* View @p v as the model is made of it: its range.bin in the output directory, else (a scan
 * from before range.bin) decoded again from its frames in @p scan_dir. */
static int load_range(struct job *j, const char *scan_dir, uint32_t v, struct scan_view *view,
                      struct scan_view_info *info)
{
    char err[SCAN_DIR_PATH_MAX + 128];
    int rc = read_range(j, j->out_dir, v, view, info, err, sizeof(err));
    if (rc == 0)
        return 0;
    if (j->cfg->keep_frames != KEEP_FRAMES_ALL) {
        j->hal->log(HAL_LOG_ERROR, "%s; the scan kept no pattern frames to decode it from", err);
        return rc;
    }
    if (rc != -ENOENT)
        j->hal->log(HAL_LOG_WARN, "%s: decoded again from its frames", err);
    return load_view(j, scan_dir, v, view, info);
}

/* Decode view @p v of @p scan_dir from its kept frames, as it was decoded live. */
static int load_view(struct job *j, const char *scan_dir, uint32_t v, struct scan_view *view,
                     struct scan_view_info *info)
{
    static struct scan_dir_view meta;
    const struct hal *hal = j->hal;
    char err[SCAN_DIR_PATH_MAX + 256];
    int rc = scan_dir_read_view(scan_dir, v, &meta, err, sizeof(err));
    if (rc == -ENOENT)
        snprintf(err, sizeof(err),
                 "%s/view_%03u: the view did not finish (no view.ini); "
                 "'scanner resume %s' takes it",
                 scan_dir, (unsigned)v, scan_dir);
    if (rc == 0)
        rc = check_frames(j, scan_dir, v, &meta, err, sizeof(err));
    if (rc == 0)
        rc = scan_job_feed_view(scan_dir, v, &j->cfg->scan, j->calib, err, sizeof(err));
    if (rc != 0) {
        hal->log(HAL_LOG_ERROR, "%s", err);
        return rc;
    }
    memset(info, 0, sizeof(*info));
    set_view(j, v);
    return scan_finish_view(j->calib, meta.angle_mdeg, view, info);
}

/* Stopped by request between views of the offline work: nothing is lost. */
static int stopped_offline(struct job *j, const char *scan_dir, uint32_t v)
{
    if (!hal_should_stop(j->hal))
        return 0;
    j->hal->log(HAL_LOG_WARN,
                "processing stopped by request before view %u; nothing of %s "
                "is lost: 'scanner process %s' starts it again",
                (unsigned)v, scan_dir, scan_dir);
    return -EINTR;
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
    struct job j;
    job_init(&j, hal, &cfg, &calib, opts, opts->out_dir ? opts->out_dir : scan_dir);
    int elsewhere = opts->out_dir != NULL && strcmp(opts->out_dir, scan_dir) != 0;
    int lock_fd;
    rc = open_out(&j,
                  !elsewhere      ? SCAN_DIR_EXISTING
                  : opts->replace ? SCAN_DIR_REPLACE
                                  : SCAN_DIR_NEW,
                  &lock_fd);
    if (rc != 0)
        return rc;
    if (elsewhere && (rc = scan_dir_keep_settings(&hal->storage, cfg.path, cfg.calibration_file,
                                                  j.out_dir)) != 0) /* how they were made */
        hal->log(HAL_LOG_ERROR, "cannot keep the settings in %s: %s", j.out_dir, strerror(-rc));
    if (rc == 0)
        rc = begin_model(&j);
    progress(&j, "process_start", -1, 0, scan_dir);
    if (rc == 0 && cfg.keep_frames != KEEP_FRAMES_ALL)
        hal->log(HAL_LOG_WARN,
                 "%s kept %s of its camera frames ([output] keep_frames = %s): its views are "
                 "registered and fused again from their range images (range.bin) as they were "
                 "decoded and coloured; [scan] and [colour] settings cannot change them",
                 scan_dir, cfg.keep_frames == KEEP_FRAMES_NONE ? "none" : "only the colour",
                 cfg.keep_frames_name);
    for (uint32_t v = 0; v < j.views && rc == 0; v++) {
        struct scan_view view;
        struct scan_view_info info;
        rc = stopped_offline(&j, scan_dir, v);
        if (rc == 0)
            rc = cfg.keep_frames == KEEP_FRAMES_ALL
                     ? load_view(&j, scan_dir, v, &view, &info)
                     : load_kept_range(&j, scan_dir, v, &view, &info);
        if (rc == 0)
            rc = scan_keep_for_registration(v, &view);
        /* the model is made of this one, not of an older range.bin (one read back from where
         * it goes is that one already) */
        if (rc == 0 && (cfg.keep_frames == KEEP_FRAMES_ALL || elsewhere) &&
            (rc = make_view_dir(&j)) == 0)
            rc = write_failed(&j, "range.bin",
                              scan_dir_write_range(&hal->storage, j.out_dir, v, &view));
        if (rc == 0) {
            char detail[HAL_MAX_PATH + 160];
            describe(detail, sizeof(detail), &info, j.view_dir);
            progress(&j, "decoded", (int)v, v + 1, detail);
        }
    }
    if (rc == 0)
        rc = make_model(&j, scan_dir);
    if (rc == 0)
        report_cost(&j, "processing");
    if (rc == 0)
        write_summary_and_report(&j, "processing");
    if (rc == 0)
        progress(&j, "process_done", -1, j.views, finished_detail(&j, path, sizeof(path)));
    scan_dir_close(lock_fd);
    return rc;
}
