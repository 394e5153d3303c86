/* The parts of a scan job (scan_job.h is its public face) and what they share: the job's state,
 * passed to each part by pointer. A view is always named by its number (job_view_dir gives its
 * folder); nothing remembers "the current view" between calls.
 *   job.c          state, clocks, the output directory, a failed write said once
 *   job_events.c   events (scan_events.h), the time left, stages, cost, summary and report,
 *                  the warning that the object is too dark (live and processed)
 *   job_live.c     on the rig: homing, each view taken and processed while the table turns
 *   job_model.c    registration, reflectance fit, fusion, the mesh's four files
 *   job_offline.c  settings of a kept scan, resume, process from the kept frames */
#ifndef JOB_H
#define JOB_H

#include "scan_events.h"
#include "scan_job.h"

#include <pthread.h>
#include <stdio.h>
#include <stddef.h>
#include <stdint.h>

#define JOB_MAX_STAGES 8u
#define JOB_MAX_WARNINGS 4u /* what the model lacks, kept for warnings.txt (job_warn) */
#define JOB_WARNING_LEN 400u

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
    struct scan_ctx *scan;       /* the view being decoded (job.c keeps the one) */
    struct reg_ctx *reg;         /* the registration of the job's views (job.c keeps the one) */
    struct reflect_pool *pool;   /* [colour] method = fit: the reflectance (job.c keeps it) */
    struct fusion_volume *vol;   /* the model's volume (job.c keeps it) */
    struct atlas *atlas;         /* its texture ([output] texture; job.c keeps it) */
    struct pending pending_view; /* where the view processed while the table turns is kept */
    struct pending *pending;     /* that view while it is processed, or NULL */
    struct eta {                 /* views finished of the current run, and when */
        uint32_t first_done, last_done;
        double first_ms, last_ms;
    } eta;
    int frames_lent; /* 1 from the fusion on: the colour frames' memory is the volume's (job.c) */
    int said_dark;   /* a view's object was too dark to decode: said once, at that view */
    int said_off_image;   /* a view's object ran off the image: said once, at that view */
    struct job_warnings { /* what the model lacks, as said (warnings.txt, report.html) */
        char text[JOB_MAX_WARNINGS][JOB_WARNING_LEN];
        unsigned n;
    } warnings;
    struct stages { /* when each stage ended (summary.ini), in the order they first did */
        const char *name[JOB_MAX_STAGES];
        double end_s[JOB_MAX_STAGES];
        unsigned n;
    } stages;
};

/* ---- job.c ---- */
/** The fusion begins: the memory of the view's colour frames becomes the volume's (job.c), the
 *  frames' pages given back first; the view context reads no colour frame from now on (it
 *  refuses one), and a view whose range.bin is gone cannot be decoded again (job_load_range). */
void job_lend_frames(struct job *j);
double job_wall_ms(void);
/** Now, UTC, as 2026-12-03T08:00:00Z. */
void job_utc_now(char *buf, size_t len);
void job_init(struct job *j, const struct hal *hal, const struct app_config *cfg,
              const struct scan_calib *calib, const struct scan_job_opts *opts,
              const char *out_dir);
/** The CPU the scanner spent since the job began, the simulator's rendering (@p sim_s, out)
 *  left out. */
double job_own_cpu_s(const struct job *j, double *sim_s);
/** The process's peak resident memory, MB. */
double job_peak_memory_mb(void);
/** View @p v's folder in the output directory. */
void job_view_dir(const struct job *j, uint32_t v, char *buf, size_t len);
/** A write of @p name into @p dir (or view @p v's folder) that failed, said once.
 *  @retval @p rc */
int job_write_failed_at(const struct job *j, const char *dir, const char *name, int rc);
int job_write_failed(const struct job *j, uint32_t v, const char *name, int rc);
/** View @p v's folder made. @retval 0 @retval -errno (said) */
int job_make_view_dir(const struct job *j, uint32_t v);
/** Lock the output directory (checked by @p mode) and sweep what a kill left there.
 *  @retval 0 @retval -errno (said) */
int job_open_out(struct job *j, enum scan_dir_mode mode, int *lock_fd);

/* ---- job_events.c ---- */
/** Write @p s to @p out as a JSON string: quoted, the quote and the backslash escaped, control
 *  characters as \u00XX (the scan's events and the calibration's result). */
void job_json_string(FILE *out, const char *s);

/** One event (scan_events.h) with its numbers as JSON fields too (@p fields: '"name":value,...'
 *  or NULL). @p view < 0: not about a view. @p done: views finished so far, for the estimate. */
void job_progress_with(struct job *j, const char *event, int view, uint32_t done,
                       const char *fields, const char *detail);
void job_progress(struct job *j, const char *event, int view, uint32_t done, const char *detail);
/** A warning about the model (an object the volume cut ...): logged, and kept for the scan's
 *  warnings.txt, which report.html and the page list (the first JOB_MAX_WARNINGS). */
void job_warn(struct job *j, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/** The end of a job that made its model: what it cost (EV_COST, "@p what N s CPU ..."),
 *  summary.ini and report.html (@p command: "scan" or "processing"), then @p event (EV_SCAN_DONE,
 *  EV_PROCESS_DONE) saying where the results are. */
void job_finished(struct job *j, const char *what, const char *command, const char *event);

/** Pixels too dark to decode that make a dark object, not a dark stripe of paint on a bright one
 *  (job_say_if_dark). */
#define JOB_DARK_PIXELS 1000u
/** Most of what the projector lights too dark to decode: @p dark pixels (JOB_DARK_PIXELS or
 *  more) outnumber the @p decoded ones. @retval 1 @retval 0 */
int job_mostly_dark(uint32_t dark, uint32_t decoded);
/** The exposure that lifts a white minus black of @p contrast_dn at @p now_us to twice
 *  @p min_contrast_dn (whole milliseconds, at most 10 s). */
uint32_t job_dark_exposure_us(uint32_t now_us, uint32_t min_contrast_dn, uint32_t contrast_dn);

/** The brightest light's 95th percentile is brought to this share of saturation_dn
 *  (job_light_exposure_us). multi and fit leave a light out where it saturates (the others see
 *  the pixel), so a few saturated readings cost less than noise in all of them: on eval-cycles'
 *  bunny the texture's error was least with about 3% of a light's pixels saturated (2.02 mean
 *  dE00 at the camera's exposure, 1.70 with 0.4% saturated, 1.66 with 3%, 1.74 with 10%:
 *  docs/colour.md). */
#define JOB_LIGHT_LEVEL_SHARE 0.95
/** The longest single-light exposure the scan chooses itself: a frame at 30 fps (a longer one
 *  would slow every capture after it). */
#define JOB_LIGHT_MAX_US 33000u
/** The single-light frames' exposure that brings what @p probe saw at @p now_us to
 *  JOB_LIGHT_LEVEL_SHARE of @p saturation_dn (only the lights' lift over the dark frame grows
 *  with the exposure), in whole milliseconds down, at most JOB_LIGHT_MAX_US, never under
 *  @p now_us (@p now_us itself where the probe saw too little: under JOB_DARK_PIXELS lit). */
uint32_t job_light_exposure_us(uint32_t now_us, const struct scan_light_probe *probe,
                               uint32_t saturation_dn);

/** Warn once when view @p v's object was too dark to decode, and how to lift it (@p live: while
 * scanning; else processing a kept scan). */
void job_say_if_dark(struct job *j, uint32_t v, const struct scan_view_info *info, int live);

/* ---- job_live.c ---- */
/** The lines a scan's config.ini gets after its file's own for what the scan chose itself: the
 *  HDR exposures of [scan] auto_exposure where the file sets no exposures_us, the single-light
 *  frames' exposure where it sets no [colour] light_exposure_us ("" when none).
 *  @retval 0 @retval -EOVERFLOW @p len too small */
int job_chosen_lines(const struct app_config *cfg, char *buf, size_t len);
/** Room for job_chosen_lines' lines: both of them, with their comments. */
#define JOB_CHOSEN_LINES_MAX 640u
/** Before a scan's first view (a new scan, or a resume of one that has none): the exposure
 *  checks of [scan] auto_exposure, which may change @p run (the patterns' HDR exposures, the
 *  single-light frames' exposure), and what they chose kept in the scan's config.ini after the
 *  lines of @p config_path (with @p calibration_path as its calibration.ini).
 *  @retval 0 @retval -EINTR stop requested (said; the rig is safe) @retval -errno storage */
int job_choose_exposures(struct job *j, struct app_config *run, const char *config_path,
                         const char *calibration_path);
/** "N points at A deg -> DIR" of a view. */
void job_describe(char *buf, size_t len, const struct scan_view_info *info, const char *dir);
int job_start_storage(const struct job *j);
/** Home the table, then take views @p first .. the last. @retval 0 @retval the first error */
int job_home_and_take_views(struct job *j, uint32_t first);

/* ---- job_model.c ---- */
/** Before the first view: the registration sized for the scan's views. */
int job_begin_model(struct job *j);
/** Once every view is in: registration, reflectance, fusion, the mesh. */
int job_make_model(struct job *j, const char *scan_dir);
/** View @p v as the model is made of it: its range image read back from @p scan_dir, recoloured
 *  from its frames while the reflectance collects its samples (once fitted, range.bin holds the
 *  colour under it). @retval 0 @retval -errno (said) */
int job_view_for_model(struct job *j, const char *scan_dir, uint32_t v, struct scan_view *view,
                       struct scan_view_info *info);

/* ---- job_texture.c ---- */
/** The views' colour on the prepared mesh (atlas.h): every vertex a view saw takes their
 *  weighted colour (16 bits), and with [output] texture the texture atlas (texture.png and
 *  mesh.mtl beside the mesh); @p said tells what was made, for the mesh's line; @p png,
 *  @p png_len: the texture's PNG for mesh.glb, the caller's to free (NULL: none). What cannot be
 *  made is said (a warning) and left out: without a texture the vertex colours stand, without
 *  the views' the fusion grid's.
 *  @retval 0 (a texture made when *png is not NULL) @retval -errno the views' colours not made */
int job_colour_mesh(struct job *j, const char *scan_dir, char *said, size_t said_len, uint8_t **png,
                    size_t *png_len);

/* ---- job_offline.c ---- */
/** Frame @p f of view @p v read from @p scan_dir into the firmware's buffer for it. */
int job_read_into_buffer(struct scan_ctx *s, const char *scan_dir, uint32_t v, uint32_t f,
                         uint32_t channels, const struct scan_params *params, uint8_t **pixels,
                         char *err, size_t err_len);
/** View @p v as the model is made of it: its range.bin, else decoded from its frames. */
int job_load_range(struct job *j, const char *scan_dir, uint32_t v, struct scan_view *view,
                   struct scan_view_info *info);
/** -EINTR (said) when a stop was asked for between views of offline work. */
int job_stopped_offline(struct job *j, const char *scan_dir, uint32_t v);

#endif
