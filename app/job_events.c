/* A scan job's events (job.h): a status line on a terminal, plain lines in a log, JSON for a
 * front end (scan_events.h names them), the estimate of the time left, the stages' times, what
 * the job cost, summary.ini and report.html at its end, and the warning that a view's object is
 * too dark to decode (job_say_if_dark). */
#define _POSIX_C_SOURCE 200809L
#include "job.h"

#include "clock_posix.h"
#include "frame_writer.h"
#include "report.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* What the job cost: the rig's time (with the simulator, the modelled rig's: its turntable and
 * frame rate) and the CPU the scanner spent, the simulator's rendering left out, split by what
 * delays the scan (in line with the rig) and what runs beside it. make bench reads this line. */
static void job_report_cost(struct job *j, const char *what)
{
    uint64_t now_us = j->start_rig_us;
    hal_clock_now_us(&j->hal->clock, &now_us);
    double sim, own = job_own_cpu_s(j, &sim);
    uint32_t views = j->views ? j->views : 1;
    char detail[400];
    if (j->views_cpu_s <= 0.0) { /* offline: one thread */
        char fields[96];
        snprintf(detail, sizeof(detail), "%s %.2f s CPU for %u views (%.3f s a view)", what, own,
                 (unsigned)j->views, own / views);
        snprintf(fields, sizeof(fields), "\"cpu_s\":%.3f,\"cpu_per_view_s\":%.4f", own,
                 own / views);
        job_progress_with(j, EV_COST, -1, j->views, fields, detail);
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
    job_progress_with(j, EV_COST, -1, j->views, fields, detail);
}

/* The bytes of the UTF-8 character at @p s (RFC 3629, section 4: no overlong form, surrogate
 * or code point beyond U+10FFFF); 0 where none begins. Stops at the first byte that does not
 * continue it, so never reads past a terminating NUL. */
static size_t utf8_length(const unsigned char *s)
{
    unsigned c = s[0];
    size_t n = c < 0x80u                  ? 1
               : c >= 0xC2u && c <= 0xDFu ? 2
               : c >= 0xE0u && c <= 0xEFu ? 3
               : c >= 0xF0u && c <= 0xF4u ? 4
                                          : 0;
    unsigned lo = c == 0xE0u ? 0xA0u : c == 0xF0u ? 0x90u : 0x80u; /* the second byte's range */
    unsigned hi = c == 0xEDu ? 0x9Fu : c == 0xF4u ? 0x8Fu : 0xBFu;
    for (size_t k = 1; k < n; k++)
        if (s[k] < (k == 1 ? lo : 0x80u) || s[k] > (k == 1 ? hi : 0xBFu))
            return 0;
    return n;
}

/* JSON text is UTF-8 (RFC 8259): a byte that is not (a path in another encoding, made by a
 * person's --out) is written as U+FFFD, so that every line still parses. */
void job_json_string(FILE *out, const char *s)
{
    fputc('"', out);
    while (*s != '\0') {
        size_t n = utf8_length((const unsigned char *)s);
        if (*s == '"' || *s == '\\')
            fprintf(out, "\\%c", *s);
        else if ((unsigned char)*s < 0x20)
            fprintf(out, "\\u%04x", (unsigned)(unsigned char)*s);
        else if (n == 0)
            fputs("\\ufffd", out);
        else
            fwrite(s, 1, n, out);
        s += n > 0 ? n : 1;
    }
    fputc('"', out);
}

/* @retval 1 for the event that ends a view's line (taken live; fused into the model). */
static int view_finished(const char *event)
{
    return strcmp(event, EV_SAVED) == 0 || strcmp(event, EV_FUSED) == 0;
}

/* Seconds left of the current run of views (taken live, decoded, or fused after the
 * registration): the measured time a view takes (from the first finished view of the run to the
 * last, so that homing and start-up do not count) times the views left, less the time already
 * spent since the last one finished. -1 until a view's time is known. Only the events that
 * finish a view move it; @p done: views finished of the run. */
static double time_left_s(struct job *j, const char *event, uint32_t done, double now_ms)
{
    struct eta *e = &j->eta;
    int finishes = view_finished(event) || strcmp(event, EV_DECODED) == 0;
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
    static const char *const ends[][2] = {{EV_SAVED, "capture"},
                                          {EV_DECODED, "decoding"},
                                          {EV_REGISTRATION, "registration"},
                                          {EV_REFLECTANCE, "reflectance fit"},
                                          {EV_MESHING, "fusion"},
                                          {EV_MESH, "meshing"}};
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

static void progress_line(struct job *j, const char *event, int view, uint32_t done,
                          const char *fields, const char *detail)
{
    double now = job_wall_ms(), elapsed_s = (now - j->start_ms) / 1000.0;
    double left_s = time_left_s(j, event, done, now);
    stage_ended(j, event, elapsed_s);
    if (j->opts->json) {
        printf("{\"event\":\"%s\",\"view\":%d,\"views\":%u,\"views_done\":%u,"
               "\"elapsed_s\":%.1f,\"left_s\":%.1f,%s%s\"detail\":",
               event, view, (unsigned)j->views, (unsigned)done, elapsed_s, left_s,
               fields != NULL ? fields : "", fields != NULL ? "," : "");
        job_json_string(stdout, detail);
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
            {EV_SCAN_START, "scanning into"},   {EV_SCAN_DONE, "scan finished:"},
            {EV_SCAN_FAILED, "scan failed:"},   {EV_PROCESS_START, "processing"},
            {EV_REGISTRATION, "registration:"}, {EV_COST, "cost:"},
            {EV_PLACE_OBJECT, ">>>"},           {EV_PROCESS_DONE, "process finished:"}};
        const char *text = event;
        for (size_t k = 0; k < sizeof(human) / sizeof(human[0]); k++)
            if (strcmp(event, human[k][0]) == 0)
                text = human[k][1];
        printf("%s %s\n", text, detail);
    }
    fflush(stdout);
}

/* One event with its numbers as JSON fields too (@p fields: '"name":value,...' or NULL, for
 * --json). @p view < 0: not about a view. @p done: views finished so far, for the estimate. */
void job_progress_with(struct job *j, const char *event, int view, uint32_t done,
                       const char *fields, const char *detail)
{
    /* a line at a time: a view is saved by its own thread while the next is taken */
    static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
    pthread_mutex_lock(&lock);
    progress_line(j, event, view, done, fields, detail);
    pthread_mutex_unlock(&lock);
}

void job_progress(struct job *j, const char *event, int view, uint32_t done, const char *detail)
{
    job_progress_with(j, event, view, done, NULL, detail);
}

void job_warn(struct job *j, const char *fmt, ...)
{
    char text[JOB_WARNING_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof(text), fmt, ap);
    va_end(ap);
    j->hal->log(HAL_LOG_WARN, "%s", text);
    if (j->warnings.n < JOB_MAX_WARNINGS)
        memcpy(j->warnings.text[j->warnings.n++], text, sizeof(text));
}

/* Where the results are, and the peak memory. */
static const char *job_finished_detail(struct job *j, char *buf, size_t len)
{
    snprintf(buf, len, "%s (mesh: %s/mesh.ply, mesh.obj, mesh.stl, mesh.glb; peak memory %.1f MB)",
             j->out_dir, j->out_dir, job_peak_memory_mb());
    return buf;
}

/* warnings.txt: the job's warnings about the model, a line each (a line of an ini file is cut at
 * 200 bytes by inih), or none: an earlier run's, processed again in place, go. */
static void job_write_warnings(struct job *j)
{
    char text[JOB_MAX_WARNINGS * (JOB_WARNING_LEN + 1)], path[SCAN_DIR_PATH_MAX];
    size_t n = 0;
    for (unsigned i = 0; i < j->warnings.n; i++) {
        size_t len = strlen(j->warnings.text[i]);
        memcpy(text + n, j->warnings.text[i], len);
        n += len;
        text[n++] = '\n';
    }
    int rc = n == 0 ? scan_dir_remove(j->out_dir, -1, SCAN_FILE_WARNINGS)
                    : scan_dir_path(path, sizeof(path), j->out_dir, -1, SCAN_FILE_WARNINGS);
    if (rc == 0 && n > 0)
        rc = hal_storage_write_file(&j->hal->storage, path, text, n);
    if (rc != 0)
        j->hal->log(HAL_LOG_WARN, "cannot write %s/%s: %s", j->out_dir, SCAN_FILE_WARNINGS,
                    strerror(-rc));
}

/* summary.ini (what report.html shows of the job: its stages, time and memory), then
 * report.html. Neither is the scan's result: a failure is said and the job goes on. */
static void job_write_summary_and_report(struct job *j, const char *command)
{
    char text[1024], path[SCAN_DIR_PATH_MAX], finished[32], err[SCAN_DIR_PATH_MAX + 64];
    job_write_warnings(j);
    job_utc_now(finished, sizeof(finished));
    double sim, cpu = job_own_cpu_s(j, &sim);
    int n = snprintf(text, sizeof(text),
                     "; what the %s took, for report.html (docs/scan-format.md)\n[summary]\n"
                     "command = %s\nfinished = %s\nviews = %u\nelapsed_s = %.1f\n"
                     "cpu_s = %.2f\npeak_memory_mb = %.1f\n[stages]\n; seconds from the start "
                     "at which each stage ended\n",
                     command, command, finished, (unsigned)j->views,
                     (job_wall_ms() - j->start_ms) / 1000.0, cpu, job_peak_memory_mb());
    for (unsigned i = 0; i < j->stages.n && n > 0 && (size_t)n < sizeof(text); i++)
        n += snprintf(text + n, sizeof(text) - (size_t)n, "%s = %.1f\n", j->stages.name[i],
                      j->stages.end_s[i]);
    int rc = n > 0 && (size_t)n < sizeof(text) ? 0 : -EOVERFLOW;
    if (rc == 0)
        rc = scan_dir_path(path, sizeof(path), j->out_dir, -1, SCAN_FILE_SUMMARY);
    if (rc == 0)
        rc = hal_storage_write_file(&j->hal->storage, path, text, (size_t)n);
    if (rc != 0)
        j->hal->log(HAL_LOG_WARN, "cannot write %s/summary.ini: %s", j->out_dir, strerror(-rc));
    if (report_write(&j->hal->storage, j->out_dir, err, sizeof(err)) != 0)
        j->hal->log(HAL_LOG_WARN, "cannot write the report: %s", err);
}

void job_finished(struct job *j, const char *what, const char *command, const char *event)
{
    char path[HAL_MAX_PATH + 32];
    job_report_cost(j, what);
    job_write_summary_and_report(j, command);
    job_progress(j, event, -1, j->views, job_finished_detail(j, path, sizeof(path)));
}

/* A dark object (black plastic, dark paint) lights too little at the camera's exposure for its
 * stripes to be told apart: its pixels are counted 'dark' (lit, white minus black under [scan]
 * min_contrast_dn), every view comes out almost empty, and the registration, given nothing,
 * failed at the end naming the calibration. Said at the first view where the pixels too dark
 * outnumber those decoded (and are JOB_DARK_PIXELS or more: a dark stripe of paint on a bright
 * object is not a dark object), with the exposure that lifts their median contrast to twice the
 * threshold: the contrast grows with the exposure. Measured (2026-12-05): the bunny at albedo
 * 0.04, every default, 0 to 98 points a view, 48,044 pixels too dark at a median contrast of 7.
 * Processing a kept scan says it too: from its frames with the exposure, from its range images
 * alone (no contrast kept) without. */
uint32_t job_dark_exposure_us(uint32_t now_us, uint32_t min_contrast_dn, uint32_t contrast_dn)
{
    /* twice the contrast the decoder needs, in whole milliseconds, at most [camera]'s bound */
    double want = (double)now_us * 2.0 * min_contrast_dn / (contrast_dn > 0 ? contrast_dn : 1);
    return (uint32_t)fmin(ceil(want / 1000.0) * 1000.0, 10000000.0);
}

uint32_t job_light_exposure_us(uint32_t now_us, const struct scan_light_probe *probe,
                               uint32_t saturation_dn)
{
    const double target_dn = JOB_LIGHT_LEVEL_SHARE * saturation_dn;
    if (probe->lit < JOB_DARK_PIXELS || probe->level_dn <= probe->dark_dn ||
        probe->level_dn >= target_dn)
        return now_us;
    /* the dark frame's level (black offset, ambient) is left as it is: the ambient grows too,
     * but a dark frame is taken at the new exposure and the target leaves room */
    double want =
        (double)now_us * (target_dn - probe->dark_dn) / (probe->level_dn - probe->dark_dn);
    want = floor(fmin(want, JOB_LIGHT_MAX_US) / 1000.0) * 1000.0;
    return want > now_us ? (uint32_t)want : now_us;
}

int job_mostly_dark(uint32_t dark, uint32_t decoded)
{
    return dark >= JOB_DARK_PIXELS && dark > decoded;
}

void job_say_if_dark(struct job *j, uint32_t v, const struct scan_view_info *info, int live)
{
    uint32_t dark = info->reason_count[SCAN_DARK], c = info->dark_contrast_dn;
    if (j->said_dark || !job_mostly_dark(dark, info->valid_points) || (live && c == 0))
        return;
    j->said_dark = 1;
    const uint32_t now_us = j->cfg->camera.exposure_us, threshold = j->cfg->scan.min_contrast_dn;
    if (c == 0) { /* a kept range image: how dark is not known */
        job_warn(j,
                 "view %u: %u pixels lit but too dark to decode against %u decoded: a dark "
                 "object? Scan it again with a longer [camera] exposure_us than %u (the scan "
                 "kept no frames to say how much longer)",
                 (unsigned)v + 1, (unsigned)dark, (unsigned)info->valid_points, (unsigned)now_us);
        return;
    }
    uint32_t want_us = job_dark_exposure_us(now_us, threshold, c);
    job_warn(j,
             "view %u: %u pixels lit but too dark to decode (white minus black %u grey levels, "
             "under [scan] min_contrast_dn = %u) against %u decoded: a dark object? %s "
             "raise [camera] exposure_us from %u to about %u (or [scan] exposures_us = %u, %u "
             "for an object with dark and bright parts)",
             (unsigned)v + 1, (unsigned)dark, (unsigned)c, (unsigned)threshold,
             (unsigned)info->valid_points, live ? "Stop the scan and" : "To scan it again,",
             (unsigned)now_us, (unsigned)want_us, (unsigned)now_us, (unsigned)want_us);
}
