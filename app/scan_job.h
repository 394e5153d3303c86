/* A whole scan: views on the rig (live) or from a scan directory (offline), progress reports,
 * and everything kept in the scan directory (docs/scan-format.md). */
#ifndef SCAN_JOB_H
#define SCAN_JOB_H

#include "config.h"
#include "hal.h"
#include "scan.h"
#include "scan_dir.h"

struct scan_job_opts {
    int json;                /**< one JSON status line per event instead of the terminal display */
    const char *out_dir;     /**< results go here (process: default the scan directory itself) */
    const char *config_path; /**< process: settings from this file instead of the scan's own
                                  config.ini (e.g. another [colour] method); NULL: the scan's */
    int clear_alarm; /**< resume: clear the turntable's alarm before homing (the operator has
                          fixed its cause: a blocked table, a jammed object) */
    int replace;     /**< scan, process --out: a scan already in the output directory is
                          replaced (without it, a directory that is not empty is refused) */
};

/** Home the table and take every configured view, saving each before the next move.
 *  @retval 0 ok @retval the first error (views finished before it are kept) */
int scan_job_live(const struct hal *hal, const struct app_config *cfg,
                  const struct scan_calib *calib, const struct scan_job_opts *opts);

/** Load the settings of the interrupted scan in @p scan_dir: its config (or @p config_path,
 *  when the scan's own names files relative to where it was) and always its kept calibration.
 *  @p config_path may change how views are processed, never how they are taken
 *  (config_plan_differs names the key). @param capturing  1: for a resume (the colour method,
 *  whose frames it takes, is kept too)
 *  @retval 0 @retval -errno with the message in @p err */
int scan_job_load_settings(const char *scan_dir, const char *config_path, int capturing,
                           struct app_config *cfg, struct scan_calib *calib, char *err,
                           size_t err_len);

/** Take the views of the scan in @p scan_dir that did not finish (no view.ini: a view is
 *  complete only once its view.ini is on disk), from the first unfinished one on, homing the
 *  table first. The model is then made by scan_job_process over all views.
 *  @retval 0 ok @retval the first error (views finished before it are kept) */
int scan_job_resume(const struct hal *hal, const struct app_config *cfg,
                    const struct scan_calib *calib, const char *scan_dir,
                    const struct scan_job_opts *opts);

/** What view.ini records of a view just taken with @p params (started, finished and wall_ms are
 *  the caller's to set). */
void scan_job_view_meta(const struct app_config *cfg, const struct scan_params *params,
                        const struct scan_calib *calib, uint32_t view,
                        const struct scan_view_info *info, struct scan_dir_view *v);

/** Feed view @p v's kept frames in @p scan_dir to @p s as the live view fed them: the patterns
 *  of @p params, then its colour frames (begins the view; finish with scan_finish_view or
 *  decode_finish). The frames are read side by side on @p threads ([scan] threads of them;
 *  NULL: one after another), each into its own buffer: the colour frames all together, the
 *  pattern frames two at a time (white and black, a bit's stripes and its inverse). @p err
 *  names a frame that is missing or wrong. @retval 0 @retval -ENOENT @retval -EINVAL */
int scan_job_feed_view(struct scan_ctx *s, const char *scan_dir, uint32_t v,
                       const struct scan_params *params, const struct scan_calib *calib,
                       const struct hal_thread *threads, char *err, size_t err_len);

/** Feed colour frame @p k (colour.h's order) of view @p v in @p scan_dir to @p s, after
 *  scan_job_feed_view: one that @p params' method does not read (the white reference reads
 *  them all). @retval 0 @retval -ENOENT @retval -EINVAL (@p err names the frame) */
int scan_job_feed_light_frame(struct scan_ctx *s, const char *scan_dir, uint32_t v, uint32_t k,
                              const struct scan_params *params, const struct scan_calib *calib,
                              char *err, size_t err_len);

/** Recompute every result of the scan in @p scan_dir from its kept frames alone.
 *  @param hal  storage, clock and log only; no device is touched
 *  @retval 0 ok @retval -errno with the file named in the log */
int scan_job_process(const struct hal *hal, const char *scan_dir, const struct scan_job_opts *opts);

/** The process's view buffers (one struct scan_ctx, kept with the job's other state): a command
 *  that takes a single view outside a job (snapshot, the white calibration) uses these. */
struct scan_ctx *scan_job_views(void);

#endif
