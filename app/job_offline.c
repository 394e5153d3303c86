/* A scan job from a scan directory (job.h): the settings it was taken with, resume, and
 * process, which makes every result again from the kept frames or range images. */
#define _POSIX_C_SOURCE 200809L
#include "job.h"

#include "frame_writer.h"
#include "gray.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

int scan_job_load_settings(const char *scan_dir, const char *config_path, int capturing,
                           struct app_config *cfg, struct scan_calib *calib, char *err,
                           size_t err_len)
{
    char path[SCAN_DIR_PATH_MAX];
    int rc = scan_dir_path(path, sizeof(path), scan_dir, -1, SCAN_FILE_CONFIG);
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
    struct app_config taken;
    char what[160];
    if (rc == 0 && config_path != NULL && access(path, F_OK) == 0) {
        rc = config_load(&taken, path, err, err_len);
        /* the exposures the scan chose itself ([scan] auto_exposure) are the scan's, as long as
         * the config given leaves them to it */
        if (rc == 0)
            config_adopt_chosen(cfg, &taken);
        if (rc == 0 && config_plan_differs(&taken, cfg, capturing, what, sizeof(what)) != 0) {
            /* the scan's own config.ini fixes how its views are taken: views taken otherwise
             * would not fit with those it has (another turn, exposure, pattern set ...) */
            snprintf(err, err_len,
                     "%s: %s was taken with %s: a %s keeps how the views are taken (views, "
                     "passes, exposure, patterns, lights, resolution); leave out --config to "
                     "use the scan's own, or take a new scan",
                     config_path, path, what, capturing ? "resume" : "re-processing");
            rc = -EINVAL;
        }
        if (rc == 0)
            cfg->scan.colour.taken_with = taken.scan.colour.method;
    }
    /* the calibration is the copy kept with the scan, whatever the config named */
    if (rc == 0)
        rc = scan_dir_path(cfg->calibration_file, sizeof(cfg->calibration_file), scan_dir, -1,
                           SCAN_FILE_CALIBRATION);
    return rc != 0 ? rc : calib_load(calib, cfg->calibration_file, cfg->light_count, err, err_len);
}

int scan_job_resume(const struct hal *hal, const struct app_config *cfg,
                    const struct scan_calib *calib, const char *scan_dir,
                    const struct scan_job_opts *opts)
{
    static struct app_config run; /* the settings the views are taken with */
    run = *cfg;
    struct job j;
    job_init(&j, hal, &run, calib, opts, scan_dir);
    char detail[64];
    int lock_fd;
    int rc = job_open_out(&j, SCAN_DIR_EXISTING, &lock_fd);
    if (rc != 0)
        return rc;
    uint32_t first = scan_dir_first_missing(scan_dir, j.views);
    snprintf(detail, sizeof(detail), "%u of %u views kept", (unsigned)first, (unsigned)j.views);
    job_progress(&j, EV_RESUME, -1, first, detail);
    if (first == 0) { /* stopped before its first view: the checks a new scan makes, made now */
        char config[SCAN_DIR_PATH_MAX], calibration[SCAN_DIR_PATH_MAX];
        rc = scan_dir_path(config, sizeof(config), scan_dir, -1, SCAN_FILE_CONFIG);
        if (rc == 0)
            rc = scan_dir_path(calibration, sizeof(calibration), scan_dir, -1,
                               SCAN_FILE_CALIBRATION);
        if (rc == 0)
            rc = job_choose_exposures(&j, &run, config, calibration);
    }
    if (rc == 0 && first < j.views) {
        rc = job_begin_model(&j); /* the model comes from scan_job_process afterwards */
        if (rc == 0)
            rc = job_start_storage(&j);
        if (rc == 0)
            rc = job_home_and_take_views(&j, first);
        frame_writer_stop();
    }
    scan_dir_close(lock_fd);
    return rc;
}

static int load_view(struct job *j, const char *scan_dir, uint32_t v, struct scan_view *view,
                     struct scan_view_info *info);

/* The frames the settings need must be the frames the view holds: a config with another
 * exposure or another number of lights would feed the wrong frame to each step. */
static int check_frames(const struct job *j, const char *scan_dir, uint32_t v,
                        const struct scan_dir_view *have, char *err, size_t err_len)
{
    struct scan_dir_view want = {0};
    scan_dir_describe_frames(&j->cfg->scan, j->calib, &want);
    for (uint32_t f = 0; f < want.frame_count; f++) {
        if (f < have->frame_count && strcmp(have->frame_name[f], want.frame_name[f]) == 0)
            continue;
        if (f >= have->frame_count) /* a view of fewer frames: [colour] method = none takes none */
            snprintf(err, err_len,
                     "%s/view_%03u/view.ini: the view took %u frames, and these settings need "
                     "frame_%02u, '%s' (other [scan] or [colour] settings than the scan was "
                     "taken with? its config.ini says how it was taken)",
                     scan_dir, (unsigned)v, (unsigned)have->frame_count, (unsigned)f,
                     want.frame_name[f]);
        else
            snprintf(err, err_len,
                     "%s/view_%03u/view.ini: frame_%02u is '%s', but these settings need '%s' "
                     "there (other [scan] or [colour] settings than the scan was taken with?)",
                     scan_dir, (unsigned)v, (unsigned)f, have->frame_name[f], want.frame_name[f]);
        return -EINVAL;
    }
    return 0;
}

/* Frame @p f of view @p v read from @p scan_dir straight into the firmware's buffer for it (fed
 * without a copy), as @p channels channels. @p pixels: out, that buffer. @retval 0
 * @retval -EINVAL no buffer for it (@p err says) @retval as scan_dir_read_frame */
int job_read_into_buffer(struct scan_ctx *s, const char *scan_dir, uint32_t v, uint32_t f,
                         uint32_t channels, const struct scan_params *params, uint8_t **pixels,
                         char *err, size_t err_len)
{
    *pixels = scan_frame_buffer(s, f);
    if (*pixels == NULL) {
        snprintf(err, err_len, "view %u: frame %u has no buffer in these settings", (unsigned)v,
                 (unsigned)f);
        return -EINVAL;
    }
    return scan_dir_read_frame(scan_dir, v, f, *pixels, (size_t)HAL_MAX_PIXELS * channels,
                               params->width, params->height, channels, err, err_len);
}

/* Frames of a view read side by side, each into its own buffer of the firmware's (their zstd
 * decoding is a fifth of `scanner process`, most of it in the 3.7 MB colour frames): item k
 * reads frame frame[k]; the caller then feeds them in the order the view took them. */
#define FEED_MAX_SIDE (COLOUR_MAX_FRAMES + 1)
struct frame_reads {
    struct scan_ctx *s;
    const char *scan_dir;
    uint32_t v;
    const struct scan_params *params;
    uint32_t count;
    uint32_t frame[FEED_MAX_SIDE], channels[FEED_MAX_SIDE];
    uint8_t *pixels[FEED_MAX_SIDE];
    int rc[FEED_MAX_SIDE];
    char err[FEED_MAX_SIDE][SCAN_DIR_PATH_MAX + 128];
};

static void read_frame(void *arg, unsigned k)
{
    struct frame_reads *r = arg;
    r->rc[k] = job_read_into_buffer(r->s, r->scan_dir, r->v, r->frame[k], r->channels[k], r->params,
                                    &r->pixels[k], r->err[k], sizeof(r->err[k]));
}

/* @p r's frames read on @p cores. @retval 0 @retval the first failing frame's error (in the
 * view's order), said in @p err */
static int read_side_by_side(struct frame_reads *r, const struct hal_thread *cores, char *err,
                             size_t err_len)
{
    hal_thread_run(cores, r->count, read_frame, r);
    for (uint32_t k = 0; k < r->count; k++) {
        if (r->rc[k] != 0) {
            snprintf(err, err_len, "%s", r->err[k]);
            return r->rc[k];
        }
    }
    return 0;
}

/* Its error texts are 5 KiB: not on the stack; one view is fed at a time (the firmware is used
 * by one thread at a time). */
static struct frame_reads reads;

/* No frame to read yet, of view @p v in @p scan_dir. */
static void reads_begin(struct scan_ctx *s, const char *scan_dir, uint32_t v,
                        const struct scan_params *params)
{
    reads = (struct frame_reads){.s = s, .scan_dir = scan_dir, .v = v, .params = params};
}

/* Frame @p f, of @p channels, to be read with the others. @retval 0 @retval -EINVAL no room */
static int reads_add(uint32_t f, uint32_t channels)
{
    if (reads.count == FEED_MAX_SIDE)
        return -EINVAL;
    reads.frame[reads.count] = f;
    reads.channels[reads.count++] = channels;
    return 0;
}

/* The pattern frames, two at a time where the second's buffer is free before the first is fed
 * (white and black, a bit's stripes and its inverse; not a bit without inverse and the next,
 * which share a buffer, nor an inverse and the next bit's stripes, whose buffer the inverse is
 * read against: with [scan] inverse_bits the pairs fell out of step there and each inverse was
 * read against the next bit's stripes), each pair read side by side and then fed in order. */
static int feed_pattern_frames(struct scan_ctx *s, const char *scan_dir, uint32_t v, uint32_t count,
                               const struct scan_params *params, const struct scan_calib *calib,
                               const struct hal_thread *cores, char *err, size_t err_len)
{
    int rc = 0;
    for (uint32_t f = 0; rc == 0 && f < count; f += reads.count) {
        reads_begin(s, scan_dir, v, params);
        for (uint32_t g = f; rc == 0 && g < count && g < f + 2u; g++) {
            if (g > f && !scan_frame_read_ahead(s, f, g))
                break;
            rc = reads_add(g, scan_frame_channels(params, calib, g));
        }
        if (rc == 0)
            rc = read_side_by_side(&reads, cores, err, err_len);
        for (uint32_t k = 0; rc == 0 && k < reads.count; k++)
            rc = scan_feed_frame(s, reads.frame[k], reads.pixels[k], reads.channels[k], NULL);
    }
    return rc;
}

/* The colour frames from @p first on (the lights the method reads, then the white colour when
 * there is one), read side by side on @p cores, then fed. @retval 0 @retval as
 * job_read_into_buffer, the first failing frame's error in @p err */
static int feed_colour_frames(struct scan_ctx *s, const char *scan_dir, uint32_t v, uint32_t first,
                              const struct scan_params *params, const struct scan_calib *calib,
                              const struct hal_thread *cores, char *err, size_t err_len)
{
    const uint32_t count = first, lights = scan_light_frame_count(params, calib);
    uint32_t channels;
    int rc = 0;
    reads_begin(s, scan_dir, v, params);
    for (uint32_t f = first; rc == 0 && (channels = scan_frame_channels(params, calib, f)) != 0;
         f++)
        if (f >= count + lights || scan_needs_light_frame(params, calib, f - count))
            rc = reads_add(f, channels); /* else taken for another method: not read back */
    if (rc == 0)
        rc = read_side_by_side(&reads, cores, err, err_len);
    for (uint32_t k = 0; rc == 0 && k < reads.count; k++) {
        uint32_t f = reads.frame[k];
        rc = f < count + lights ? scan_feed_light_frame(s, f - count, reads.pixels[k])
                                : scan_feed_white_colour(s, reads.pixels[k]);
    }
    return rc;
}

int scan_job_feed_view(struct scan_ctx *s, const char *scan_dir, uint32_t v,
                       const struct scan_params *params, const struct scan_calib *calib,
                       const struct hal_thread *threads, char *err, size_t err_len)
{
    struct gray_layout layout;
    scan_layout(params, calib, &layout);
    uint32_t count = gray_layout_count(&layout);
    struct hal_thread cores = scan_cores(threads, params);
    int rc = scan_begin_view(s, params, calib);
    if (rc == 0)
        rc = feed_pattern_frames(s, scan_dir, v, count, params, calib, &cores, err, err_len);
    if (rc == 0)
        rc = feed_colour_frames(s, scan_dir, v, count, params, calib, &cores, err, err_len);
    return rc;
}

int scan_job_feed_light_frame(struct scan_ctx *s, const char *scan_dir, uint32_t v, uint32_t k,
                              const struct scan_params *params, const struct scan_calib *calib,
                              char *err, size_t err_len)
{
    struct gray_layout layout;
    scan_layout(params, calib, &layout);
    uint32_t f = gray_layout_count(&layout) + k;
    uint8_t *pixels;
    if (k >= scan_light_frame_count(params, calib)) {
        snprintf(err, err_len, "view %u: no colour frame %u in these settings", (unsigned)v,
                 (unsigned)k);
        return -EINVAL;
    }
    int rc = job_read_into_buffer(s, scan_dir, v, f, 3, params, &pixels, err, err_len);
    return rc == 0 ? scan_feed_light_frame(s, k, pixels) : rc;
}

/* View @p v read back from its range.bin in @p dir, with what job_describe() says of it (the
 * reader has checked that the valid pixels are the header's count). @retval 0 @retval -ENOENT
 * none @retval -EINVAL (@p err says) */
static int read_range(struct job *j, const char *dir, uint32_t v, struct scan_view *view,
                      struct scan_view_info *info, char *err, size_t err_len)
{
    int rc = scan_dir_read_range(j->scan, dir, v, j->cfg->scan.width, j->cfg->scan.height, view,
                                 err, err_len);
    if (rc == 0) {
        memset(info, 0, sizeof(*info));
        info->angle_mdeg = view->angle_mdeg;
        info->valid_points = view->range.valid_count;
    }
    return rc;
}

/* View @p v of a scan that kept no pattern frames: its range.bin in @p scan_dir, its pixels
 * counted by reason as the decoder counts them (job_say_if_dark reads the dark ones; the reader
 * has refused a reason beyond SCAN_REASON_COUNT). */
static int load_kept_range(struct job *j, const char *scan_dir, uint32_t v, struct scan_view *view,
                           struct scan_view_info *info)
{
    char err[SCAN_DIR_PATH_MAX + 128];
    int rc = read_range(j, scan_dir, v, view, info, err, sizeof(err));
    if (rc != 0) {
        j->hal->log(HAL_LOG_ERROR, "%s; the scan kept no pattern frames to decode it from", err);
        return rc;
    }
    for (size_t i = 0, n = (size_t)view->width * view->height; i < n; i++)
        info->reason_count[view->maps.reason[i]]++;
    return 0;
}

/* View @p v as the model is made of it: its range.bin in the output directory, else (a scan
 * from before range.bin) decoded again from its frames in @p scan_dir. */
int job_load_range(struct job *j, const char *scan_dir, uint32_t v, struct scan_view *view,
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
    if (j->frames_lent) { /* the decoder's colour frames are the volume now (job.c) */
        j->hal->log(HAL_LOG_ERROR,
                    "%s: it went while the model was being made, and cannot be decoded again "
                    "now; 'scanner process %s' makes the model again",
                    err, scan_dir);
        return rc != -ENOENT ? rc : -EIO;
    }
    if (rc != -ENOENT)
        j->hal->log(HAL_LOG_WARN, "%s: decoded again from its frames", err);
    return load_view(j, scan_dir, v, view, info);
}

/* Decode view @p v of @p scan_dir from its kept frames, as it was decoded live. */
static int load_view(struct job *j, const char *scan_dir, uint32_t v, struct scan_view *view,
                     struct scan_view_info *info)
{
    struct scan_dir_view meta;
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
        rc = scan_job_feed_view(j->scan, scan_dir, v, &j->cfg->scan, j->calib, &j->hal->thread, err,
                                sizeof(err));
    if (rc != 0) {
        hal->log(HAL_LOG_ERROR, "%s", err);
        return rc;
    }
    memset(info, 0, sizeof(*info));
    return scan_finish_view(j->scan, &j->hal->thread, j->calib, meta.angle_mdeg, view, info);
}

/* Stopped by request between views of the offline work: nothing is lost. */
int job_stopped_offline(struct job *j, const char *scan_dir, uint32_t v)
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
    struct app_config cfg;
    struct scan_calib calib;
    char err[512];
    int rc = scan_job_load_settings(scan_dir, opts->config_path, 0, &cfg, &calib, err, sizeof(err));
    if (rc != 0) {
        hal->log(HAL_LOG_ERROR, "%s", err);
        return rc;
    }
    struct job j;
    job_init(&j, hal, &cfg, &calib, opts, opts->out_dir ? opts->out_dir : scan_dir);
    int elsewhere = opts->out_dir != NULL && strcmp(opts->out_dir, scan_dir) != 0;
    int lock_fd;
    rc = job_open_out(&j,
                      !elsewhere      ? SCAN_DIR_EXISTING
                      : opts->replace ? SCAN_DIR_REPLACE
                                      : SCAN_DIR_NEW,
                      &lock_fd);
    if (rc != 0)
        return rc;
    /* summary.ini says every output is written (docs/scan-format.md): they are made again */
    scan_dir_remove(j.out_dir, -1, SCAN_FILE_SUMMARY);
    char chosen[JOB_CHOSEN_LINES_MAX];
    if (elsewhere && ((rc = job_chosen_lines(&cfg, chosen, sizeof(chosen))) != 0 ||
                      (rc = scan_dir_keep_settings(&hal->storage, cfg.path, cfg.calibration_file,
                                                   j.out_dir, chosen)) != 0)) /* how made */
        hal->log(HAL_LOG_ERROR, "cannot keep the settings in %s: %s", j.out_dir, strerror(-rc));
    if (rc == 0)
        rc = job_begin_model(&j);
    job_progress(&j, EV_PROCESS_START, -1, 0, scan_dir);
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
        rc = job_stopped_offline(&j, scan_dir, v);
        if (rc == 0)
            rc = cfg.keep_frames == KEEP_FRAMES_ALL
                     ? load_view(&j, scan_dir, v, &view, &info)
                     : load_kept_range(&j, scan_dir, v, &view, &info);
        if (rc == 0) {
            job_say_if_dark(&j, v, &info, 0);
            rc = scan_keep_for_registration(j.reg, v, &view);
        }
        /* the model is made of this one, not of an older range.bin (one read back from where
         * it goes is that one already) */
        if (rc == 0 && (cfg.keep_frames == KEEP_FRAMES_ALL || elsewhere) &&
            (rc = job_make_view_dir(&j, v)) == 0)
            rc = job_write_failed(&j, v, SCAN_FILE_RANGE,
                                  scan_dir_write_range(&hal->storage, j.out_dir, v, &view));
        if (rc == 0) {
            char detail[HAL_MAX_PATH + 160], dir[SCAN_DIR_PATH_MAX];
            job_view_dir(&j, v, dir, sizeof(dir));
            job_describe(detail, sizeof(detail), &info, dir);
            job_progress(&j, EV_DECODED, (int)v, v + 1, detail);
        }
    }
    if (rc == 0)
        rc = job_make_model(&j, scan_dir);
    if (rc == 0)
        job_finished(&j, "processing", "processing", EV_PROCESS_DONE);
    scan_dir_close(lock_fd);
    return rc;
}
