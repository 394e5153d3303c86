/* A scan job on the rig (job.h): home the table, take each view and process it while the table
 * turns to the next, the second pass, and the folder a new scan goes to. */
#define _POSIX_C_SOURCE 200809L
#include "job.h"

#include "answer.h"
#include "board.h"
#include "clock_posix.h"
#include "frame_writer.h"
#include "image_io.h"
#include "thread_posix.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

/* Frames a scan keeps ([output] keep_frames): "colour" keeps the white pattern (the colour of
 * method none, the white of the others), the light frames and an HDR scan's colour frame. */
static int keeps_frame(const struct job *j, uint32_t frame)
{
    if (j->cfg->keep_frames != KEEP_FRAMES_COLOUR)
        return j->cfg->keep_frames == KEEP_FRAMES_ALL;
    return scan_frame_channels(&j->cfg->scan, j->calib, frame) == 3;
}

/* The view being captured, for the frame sink: its frames go to its folder. */
struct capture {
    struct job *j;
    uint32_t view;
    char dir[SCAN_DIR_PATH_MAX];
};

/* A frame goes to the storage thread (a grey pattern frame copied: the decoder's lasts only until
 * the next, scan_frame_sink); a write of an earlier frame that failed is said here, once, with
 * its file. */
static int save_frame(void *priv, uint32_t pattern, const uint8_t *pixels, uint32_t width,
                      uint32_t height, uint32_t channels)
{
    const struct capture *c = priv;
    const struct job *j = c->j;
    char failed[SCAN_DIR_PATH_MAX] = "";
    if (!keeps_frame(j, pattern))
        return 0;
    int rc = frame_writer_put(j->out_dir, c->view, pattern, pixels, width, height, channels,
                              (enum scan_frame_format)j->cfg->frame_format, channels == 1, failed,
                              sizeof(failed));
    if (rc != 0)
        j->hal->log(HAL_LOG_ERROR, "cannot write %s: %s", failed[0] ? failed : c->dir,
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
    struct scan_dir_view v;
    const struct job *j = p->j;
    scan_job_view_meta(j->cfg, &j->cfg->scan, j->calib, p->view, &p->info, &v);
    snprintf(v.started, sizeof(v.started), "%s", p->started);
    job_utc_now(v.finished, sizeof(v.finished));
    v.wall_ms = ms;
    return job_write_failed_at(j, p->view_dir, SCAN_FILE_VIEW,
                               scan_dir_write_view(&j->hal->storage, j->out_dir, p->view, &v));
}

void job_describe(char *buf, size_t len, const struct scan_view_info *info, const char *dir)
{
    snprintf(buf, len, "%u points at %.1f deg -> %s", (unsigned)info->valid_points,
             info->angle_mdeg / 1000.0, dir);
}

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

/* The object running off the image is said at the first view that shows it, at the table's pose
 * (the registration has not run): the person can stop and move the camera instead of waiting for
 * the scan's end, where the model says it too (job_model.c). */
static void say_if_off_image(struct job *j, uint32_t v, const struct scan_view *view)
{
    struct frame_xform pose;
    if (j->said_off_image)
        return;
    frame_object_from_camera(j->calib, view->angle_mdeg, &pose);
    if (fusion_border_points(&j->cfg->fusion, &pose, &view->maps, &view->range) <
        FUSION_EDGE_POINTS)
        return;
    j->said_off_image = 1;
    j->hal->log(HAL_LOG_WARN,
                "view %u: the object runs off the camera's image: what lies beyond its edge will "
                "not be scanned (stop the scan and place the camera farther away, or lay the "
                "object down)",
                (unsigned)v + 1);
}

/* Decode a captured view, keep its frames and range image, then its view.ini last (its
 * presence says the view is complete). @retval 0 @retval -errno (said) */
static int save_view(struct pending *p)
{
    struct job *j = p->j;
    const struct hal *hal = j->hal;
    struct scan_view view;
    char detail[HAL_MAX_PATH + 160], fields[96];
    int rc =
        scan_finish_view(j->scan, &j->hal->thread, j->calib, p->info.angle_mdeg, &view, &p->info);
    int rc_frames = flush_frames(j); /* nothing writes into the view's directory after this */
    if (rc == 0)
        rc = rc_frames;
    if (rc != 0) { /* the layer that met the fault has said what it was */
        view_not_finished(j, p->view, p->info.angle_mdeg, rc);
        return rc;
    }
    job_progress(j, EV_SAVING, (int)p->view, p->view, "");
    say_if_off_image(j, p->view, &view);
    job_say_if_dark(j, p->view, &p->info, 1);
    rc = scan_keep_for_registration(j->reg, p->view,
                                    &view); /* the model is made once every view is in */
    if (rc == 0) /* what the model is made of, so that it is not decoded again */
        rc = job_write_failed_at(j, p->view_dir, SCAN_FILE_RANGE,
                                 scan_dir_write_range(&hal->storage, j->out_dir, p->view, &view));
    if (rc == 0)
        rc = write_view_meta(p, job_wall_ms() - p->t0_ms);
    if (rc != 0)
        return rc;
    job_describe(detail, sizeof(detail), &p->info, p->view_dir);
    snprintf(fields, sizeof(fields), "\"points\":%u,\"angle_deg\":%.3f",
             (unsigned)p->info.valid_points, p->info.angle_mdeg / 1000.0);
    job_progress_with(j, EV_SAVED, (int)p->view, p->view + 1, fields, detail);
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
    struct pending *p = &j->pending_view; /* one at a time */
    *p = (struct pending){.j = j, .view = v, .t0_ms = t0_ms, .info = *info};
    job_view_dir(j, v, p->view_dir, sizeof(p->view_dir));
    snprintf(p->started, sizeof(p->started), "%s", started);
    int rc = thread_posix_start(&p->thread, 0, process_view, p);
    if (rc == 0) {
        j->pending = p;
        return 0;
    }
    j->hal->log(HAL_LOG_WARN,
                "cannot start a thread (%s): view %u is processed before the "
                "table turns",
                strerror(-rc), (unsigned)v);
    process_view(p);
    return view_processed(j, p);
}

static int live_view(struct job *j, uint32_t v)
{
    const struct hal *hal = j->hal;
    uint32_t k = v % j->cfg->views; /* the view's place in its pass */
    int32_t target = (int32_t)((j->cfg->start_angle_deg + 360.0 * k / j->cfg->views) * 1000.0);
    char detail[HAL_MAX_PATH + 160], started[32];
    snprintf(detail, sizeof(detail), "to %.1f deg", target / 1000.0);
    job_progress(j, EV_MOVING, (int)v, v, detail);
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
    struct capture c = {.j = j, .view = v}; /* the frame sink's, while the view is taken */
    job_view_dir(j, v, c.dir, sizeof(c.dir));
    rc = scan_dir_begin_view(&hal->storage, j->out_dir, v); /* no view.ini of an earlier take */
    if (rc != 0) {
        hal->log(HAL_LOG_ERROR, "cannot prepare %s: %s", c.dir, strerror(-rc));
        return rc;
    }
    job_utc_now(started, sizeof(started));
    job_progress(j, EV_CAPTURING, (int)v, v, "");
    struct scan_frame_sink sink = {save_frame, &c};
    struct scan_view_info info;
    double t0 = job_wall_ms();
    rc = scan_capture_view(j->scan, hal, &j->cfg->scan, j->calib, st.position_mdeg, &sink, &info);
    /* the simulator's truth of this view while the table is still at its angle */
    if (rc == 0)
        rc = job_write_failed_at(j, c.dir, "(the simulator's truth)",
                                 board_write_view_extras(hal, c.dir));
    if (rc != 0) {       /* the layer that met the fault has said what it was */
        flush_frames(j); /* nothing writes into the view's directory after this */
        view_not_finished(j, v, st.position_mdeg, rc);
        return rc;
    }
    return start_processing(j, v, started, t0, &info);
}

/* While the person lays the object for a second pass (the page asks: --json), what the camera
 * sees about once a second as DIR/live.png (a temporary file renamed), which the page shows
 * beside its question; removed once answered. */
struct live_picture {
    struct job *j;
    double next_ms; /* the wall clock's: a simulated rig's clock stands still while it waits */
    int off;        /* the camera gave no picture: said once, no more tried */
    char path[HAL_MAX_PATH + 16]; /* DIR/live.png */
};

static void live_picture_take(void *ctx)
{
    struct live_picture *l = ctx;
    const struct hal *hal = l->j->hal;
    double now_ms = job_wall_ms();
    if (l->off || now_ms < l->next_ms)
        return;
    const uint8_t *rgb;
    const struct scan_params *p = &l->j->cfg->scan;
    /* image_write_png replaces the file whole: the page never reads half a picture */
    if (scan_snapshot(l->j->scan, hal, p, l->j->calib, &rgb) != 0 ||
        image_write_png(&hal->storage, l->path, rgb, p->width, p->height, 3) != 0) {
        hal->log(HAL_LOG_WARN, "no live picture while the scan waits (the scan goes on)");
        l->off = 1;
        return;
    }
    l->next_ms = now_ms + 1000.0;
}

/* The person lays the object for the second pass: asked, and the answer waited for, on a rig
 * (and on the simulator with [sim] person = asked); the simulated person otherwise does it at
 * once. @retval 0 @retval -EINTR the person stopped (Ctrl-D) @retval -errno */
static int ask_for_second_pass(struct job *j)
{
    char err[256];
    const char *detail = "pass 2 of 2: lay the object on its side (another way than before), "
                         "near the middle of the table";
    struct board_target t = {.kind = BOARD_TARGET_OBJECT, .pass = 2};
    job_progress(j, EV_PLACE_OBJECT, -1, 0, detail);
    int rc = board_place_target((struct hal *)j->hal, &t, err, sizeof(err));
    if (rc == 0 && strcmp(j->cfg->sim.person, "asked") != 0)
        return 0;
    if (rc != 0 && rc != -ENOSYS) {
        j->hal->log(HAL_LOG_ERROR, "%s", err);
        return rc;
    }
    if (!j->opts->json) { /* with --json the event is the question (the page shows it) */
        printf("%s; press Enter when it is done (Ctrl-D stops; the views so far are kept).\n",
               detail);
        fflush(stdout);
    }
    static const char *const answers[] = {"continue"};
    struct live_picture live = {.j = j};
    snprintf(live.path, sizeof(live.path), "%s/" SCAN_FILE_LIVE, j->out_dir);
    unsigned which;
    rc = answer_wait(j->hal, answers, 1, "Enter (or 'continue') when the object is laid",
                     j->opts->json ? live_picture_take : NULL, &live, &which);
    unlink(live.path);
    return rc;
}

/* The storage thread that keeps the frames while the next are taken. */
int job_start_storage(const struct job *j)
{
    int rc = frame_writer_start(&j->hal->storage);
    if (rc != 0)
        j->hal->log(HAL_LOG_ERROR, "cannot start the storage thread: %s", strerror(-rc));
    return rc;
}

/* Home the table, then take views @p first .. the last, each processed and saved while the
 * table turns to the next; a two-pass scan asks for the object to be laid for the second pass
 * (the first pass saved), and homes again. */
int job_home_and_take_views(struct job *j, uint32_t first)
{
    const struct hal *hal = j->hal;
    int rc = 0;
    if (j->cfg->passes == 2 && first >= j->cfg->views) /* resumed in the second pass */
        rc = ask_for_second_pass(j);
    if (rc == 0)
        job_progress(j, EV_HOMING, (int)first, first, "");
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

int job_chosen_lines(const struct app_config *cfg, char *buf, size_t len)
{
    buf[0] = '\0';
    int n = 0;
    if (cfg->scan.exposure_count > 0 && !cfg->exposures_us.given) {
        char list[SCAN_MAX_EXPOSURES * 12] = "";
        for (uint32_t e = 0; e < cfg->scan.exposure_count; e++)
            snprintf(list + strlen(list), sizeof(list) - strlen(list), e > 0 ? ", %u" : "%u",
                     (unsigned)cfg->scan.exposures_us[e]);
        n = snprintf(buf, len,
                     "\n; the exposures every pattern was taken at: the config set none, and most "
                     "of what\n; the projector lit was too dark to decode at the first "
                     "([scan] auto_exposure)\n[scan]\nexposures_us = %s\n",
                     list);
        if (n < 0 || (size_t)n >= len)
            return -EOVERFLOW;
    }
    if (cfg->scan.colour.light_exposure_us > 0 && !cfg->light_exposure_us.given) {
        int m = snprintf(buf + n, len - (size_t)n,
                         "\n; the exposure each light alone was taken at: the config set none, "
                         "and the\n; lights called for it ([scan] auto_exposure)\n[colour]\n"
                         "light_exposure_us = %u\n",
                         (unsigned)cfg->scan.colour.light_exposure_us);
        if (m < 0 || (size_t)m >= len - (size_t)n)
            return -EOVERFLOW;
    }
    return 0;
}

/* The exposure check (probe_dark): @p run's patterns at @p now_us and @p want_us. */
static void take_hdr(struct app_config *run, uint32_t now_us, uint32_t want_us)
{
    run->scan.exposures_us[0] = now_us;
    run->scan.exposures_us[1] = want_us;
    run->scan.exposure_count = 2;
}

/* Still too dark at the longer exposure: a tenth of what it lights (and JOB_DARK_PIXELS). */
#define DARK_SHARE_LEFT 0.1

/* [scan] auto_exposure: before the first view, a white and a black frame at [camera]
 * exposure_us; where most of what the projector lights is too dark to decode (as
 * job_say_if_dark would say after the whole turn, every view all but empty), pairs at the
 * exposure that lifts the dark pixels' median contrast to twice the threshold, once more from
 * there while a tenth is still too dark (at a longer exposure more of the object is lit: its
 * grazing parts), and if the camera takes it, every pattern is also taken at the last (HDR: per
 * pixel the longest exposure not saturated, so a bright part loses nothing). Not where the file
 * sets exposures_us (empty too: the person chose), nor where the camera cannot change its
 * exposure. Measured: the bunny at albedo 0.04 with every default, 10 ms: 54,338 of 56,199 lit
 * pixels too dark; 29 ms: 31,172 of 148,168; 73 ms. @retval 0 (@p run as the views are to be
 * taken) @retval -EINTR stop requested */
static int probe_dark(struct job *j, struct app_config *run)
{
    const struct hal *hal = j->hal;
    if (!run->auto_exposure || run->scan.exposure_count > 0 || run->exposures_us.given)
        return 0;
    const uint32_t now_us = run->camera.exposure_us;
    struct scan_contrast first, at;
    int rc = scan_probe_contrast(j->scan, hal, &run->scan, j->calib, now_us, &first);
    if (rc != 0 && rc != -EINTR)
        hal->log(HAL_LOG_WARN, "the exposure check took no frames (%s): the exposure as set",
                 strerror(-rc));
    if (rc != 0 || !job_mostly_dark(first.dark, first.lit - first.dark))
        return rc == -EINTR ? rc : 0;
    uint32_t last_us = now_us;
    at = first;
    for (int step = 0; step < 2; step++) {
        uint32_t want_us =
            job_dark_exposure_us(last_us, run->scan.min_contrast_dn, at.dark_median_dn);
        if (step > 0 && (at.dark < JOB_DARK_PIXELS || at.dark <= DARK_SHARE_LEFT * at.lit))
            break;
        if (want_us <= last_us)
            break;
        struct scan_contrast next;
        rc = scan_probe_contrast(j->scan, hal, &run->scan, j->calib, want_us, &next);
        if (rc == -EINTR)
            return rc;
        if (rc != 0) {
            hal->log(HAL_LOG_WARN, "the exposure check: the camera could not take %u us (%s)",
                     (unsigned)want_us, strerror(-rc));
            break;
        }
        last_us = want_us;
        at = next;
    }
    if (last_us == now_us) /* the views will say it (job_say_if_dark) */
        return 0;
    take_hdr(run, now_us, last_us);
    char msg[160];
    if (scan_check(&run->scan, j->calib, msg, sizeof(msg)) != 0) {
        run->scan.exposure_count = 0;
        hal->log(HAL_LOG_WARN,
                 "a dark object, but its longer exposure cannot be taken (%s): the "
                 "exposure as set",
                 msg);
        return 0;
    }
    hal->log(HAL_LOG_INFO,
             "a dark object: %u of the %u pixels the projector lights are too dark to decode at "
             "%u us (white minus black %u grey levels), %u of %u at %u us; every pattern is also "
             "taken at %u us ([scan] exposures_us = %u, %u, kept in the scan's config.ini; "
             "auto_exposure = 0 leaves the exposure as set)",
             (unsigned)first.dark, (unsigned)first.lit, (unsigned)now_us,
             (unsigned)first.dark_median_dn, (unsigned)at.dark, (unsigned)at.lit, (unsigned)last_us,
             (unsigned)last_us, (unsigned)now_us, (unsigned)last_us);
    return 0;
}

/* [scan] auto_exposure for the colour: before the first view, a dark frame and each light alone
 * at [camera] exposure_us; where the brightest light leaves the object far under saturation,
 * the single-light frames (and their dark frame) are taken longer, at the exposure that brings
 * it near (job_light_exposure_us): each light's reading then carries less of the camera's
 * noise, which in single-light frames at the camera's exposure was the larger part of a matte
 * object's colour error (docs/colour.md, "Where the error is"). Not where the file sets
 * light_exposure_us (empty too: no), nor for the methods that read no single-light frame. @retval 0
 * (@p run as the views are to be taken) @retval -EINTR stop requested */
static int probe_lights(struct job *j, struct app_config *run)
{
    const struct hal *hal = j->hal;
    if (!run->auto_exposure || run->light_exposure_us.given || run->light_count == 0 ||
        run->scan.colour.method < COLOUR_MULTI)
        return 0;
    const uint32_t now_us = run->camera.exposure_us;
    struct scan_light_probe probe;
    int rc = scan_probe_lights(j->scan, hal, &run->scan, j->calib, &probe);
    if (rc == -EINTR)
        return rc;
    if (rc != 0) {
        hal->log(HAL_LOG_WARN,
                 "the lights' exposure check took no frames (%s): the exposure as set",
                 strerror(-rc));
        return 0;
    }
    uint32_t want_us = job_light_exposure_us(now_us, &probe, run->scan.saturation_dn);
    if (want_us == now_us) {
        char level[48];
        if (probe.level_dn == DECODE_SATURATED)
            snprintf(level, sizeof(level), "saturation");
        else
            snprintf(level, sizeof(level), "%u of %u grey levels", (unsigned)probe.level_dn,
                     (unsigned)run->scan.saturation_dn);
        hal->log(HAL_LOG_INFO,
                 "the lights at %u us: the brightest (light %u) brings the object to %s (95th "
                 "percentile of what it lights, %u pixels): each light alone is taken at it",
                 (unsigned)now_us, (unsigned)probe.light, level, (unsigned)probe.lit);
        return 0;
    }
    /* a camera that cannot change its exposure (-ENOSYS) is found here, not in the first view */
    const uint32_t gain = run->scan.colour.gain_milli;
    rc = hal_cam_set_exposure(&hal->camera, want_us, gain);
    if (rc == 0 && (rc = hal_cam_set_exposure(&hal->camera, now_us, gain)) != 0) {
        hal->log(HAL_LOG_ERROR, "camera: cannot set the exposure back to %u us: %s",
                 (unsigned)now_us, strerror(-rc));
        return rc; /* no view is taken at an exposure it was not meant for */
    }
    char msg[160] = "";
    if (rc != 0)
        snprintf(msg, sizeof(msg), "the camera: %s", strerror(-rc));
    run->scan.colour.light_exposure_us = want_us;
    if (rc != 0 || scan_check(&run->scan, j->calib, msg, sizeof(msg)) != 0) {
        run->scan.colour.light_exposure_us = 0;
        hal->log(HAL_LOG_WARN,
                 "the lights call for %u us, which cannot be taken (%s): the exposure as set",
                 (unsigned)want_us, msg);
        return 0;
    }
    hal->log(HAL_LOG_INFO,
             "the lights at %u us: the brightest (light %u) brings the object to %u of %u grey "
             "levels (95th percentile, dark %u); each light alone is taken at %u us ([colour] "
             "light_exposure_us, kept in the scan's config.ini; auto_exposure = 0 leaves the "
             "exposure as set)",
             (unsigned)now_us, (unsigned)probe.light, (unsigned)probe.level_dn,
             (unsigned)run->scan.saturation_dn, (unsigned)probe.dark_dn, (unsigned)want_us);
    return 0;
}

int job_choose_exposures(struct job *j, struct app_config *run, const char *config_path,
                         const char *calibration_path)
{
    char chosen[JOB_CHOSEN_LINES_MAX] = "";
    int rc = probe_dark(j, run);
    if (rc == 0)
        rc = probe_lights(j, run);
    if (rc == 0)
        rc = job_chosen_lines(run, chosen, sizeof(chosen));
    if (rc == 0 && chosen[0] != '\0')
        rc = scan_dir_keep_settings(&j->hal->storage, config_path, calibration_path, j->out_dir,
                                    chosen);
    if (rc == -EINTR)
        j->hal->log(HAL_LOG_WARN,
                    "scan stopped by request before its first view: nothing taken; 'scanner "
                    "resume %s' takes the views",
                    j->out_dir);
    return rc;
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
    char auto_dir[HAL_MAX_PATH + 32];
    const char *name = NULL;
    if (opts->out_dir == NULL) {
        int rc = hal_storage_mkdir_p(&hal->storage, cfg->output_dir);
        if (rc == 0)
            rc = scan_dir_make_new(cfg->output_dir, auto_dir, sizeof(auto_dir), &name);
        if (rc != 0) {
            hal->log(HAL_LOG_ERROR, "cannot name a new scan folder in %s: %s", cfg->output_dir,
                     strerror(-rc));
            return rc;
        }
    }
    static struct app_config run; /* the settings the views are taken with (probe_dark) */
    run = *cfg;
    struct job j;
    job_init(&j, hal, &run, calib, opts, opts->out_dir ? opts->out_dir : auto_dir);
    int lock_fd;
    int rc = job_open_out(&j, opts->replace ? SCAN_DIR_REPLACE : SCAN_DIR_NEW, &lock_fd);
    if (rc != 0)
        return rc;
    if (name != NULL)
        link_latest(hal, cfg->output_dir, name);
    /* the settings first, as the file has them: a scan stopped in the exposure check is still a
     * scan to resume; then again with what the check chose */
    rc = scan_dir_keep_settings(&hal->storage, cfg->path, cfg->calibration_file, j.out_dir, NULL);
    if (rc == 0)
        rc = job_choose_exposures(&j, &run, cfg->path, cfg->calibration_file);
    if (rc == -EINTR) /* the rig is safe (scan_probe_contrast, scan_probe_lights); said */
        goto out_unlock;
    if (rc != 0) {
        hal->log(HAL_LOG_ERROR, "cannot set up the scan directory %s: %s", j.out_dir,
                 strerror(-rc));
        goto out_unlock;
    }
    rc = job_begin_model(&j);
    if (rc == 0)
        rc = job_write_failed_at(&j, j.out_dir, "(the simulator's truth)",
                                 board_write_scan_extras(hal, j.out_dir));
    if (rc != 0)
        goto out_unlock;
    job_progress(&j, EV_SCAN_START, -1, 0, j.out_dir);
    rc = job_start_storage(&j);
    if (rc == 0)
        rc = job_home_and_take_views(&j, 0);
    frame_writer_stop();
    if (rc == 0)
        rc = job_make_model(&j, j.out_dir);
    if (rc == 0)
        job_finished(&j, "the scan", "scan", EV_SCAN_DONE);
    else if (opts->json)
        job_progress(&j, EV_SCAN_FAILED, -1, 0, strerror(-rc));
out_unlock:
    scan_dir_close(lock_fd);
    return rc;
}
