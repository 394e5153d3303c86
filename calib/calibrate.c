/* `scanner calibrate`: the procedure a person follows at the rig, its captures, the printable
 * board and the verification scan (the computation is app/calib_solve.c). */
#define _POSIX_C_SOURCE 200809L
#include "calibrate.h"

#include "answer.h"
#include "board.h"
#include "calib_cv.h"
#include "calib_priv.h"
#include "config.h"
#include "decode.h"
#include "image_io.h"
#include "scan.h"
#include "scan_dir.h"
#include "scan_job.h"
#include "job.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the person's steps ---- */

struct capture {
    struct hal *hal;
    const struct app_config *cfg;
    const struct scan_calib *guess;
    const char *dir;
    uint32_t view;
    uint32_t kept; /* views on disk (a step taken again starts below it) */
    struct scan_params params;
    struct calcv_board board;
    uint8_t *sheet; /* the board as printed, for the simulated person */
    int sheet_w, sheet_h;
    int person;          /* 1: a person places the targets (a rig), and may take a view again */
    int board_found;     /* the last board capture showed the board */
    int json;            /* --json: events on stdout (docs/api.md), answers on stdin: the page */
    int live;            /* a live picture while the person places the board (json only) */
    double live_next_ms; /* job_wall_ms when the next live picture is due */
};

static int save_frame(void *priv, uint32_t pattern, const uint8_t *pixels, uint32_t width,
                      uint32_t height, uint32_t channels)
{
    struct capture *c = priv;
    /* PNG: calibration captures are few, and any image tool opens them */
    int rc = scan_dir_write_frame(&c->hal->storage, c->dir, c->view, pattern, pixels, width, height,
                                  channels, SCAN_FRAMES_PNG);
    if (rc != 0)
        c->hal->log(HAL_LOG_ERROR, "cannot write frame %u of %s/view_%03u: %s", (unsigned)pattern,
                    c->dir, (unsigned)c->view, strerror(-rc));
    return rc;
}

/* Answers a person gives: the first is Enter's. */
static const char *const answers_place[] = {"continue", "back"};
static const char *const answers_retry[] = {"again", "skip", "s", "S"};

/* The board in the picture @p rgb (the camera's size): its corners, or why not (@p why).
 * @retval 1 found */
static int find_board(const struct capture *c, const uint8_t *rgb, uint32_t width, uint32_t height,
                      struct calcv_corners *corners, char *why, size_t why_len)
{
    static uint8_t grey[HAL_MAX_PIXELS];
    decode_rgb_to_grey(rgb, grey, (size_t)width * height, 256);
    return calcv_find_corners(&c->board, grey, (int)width, (int)height,
                              (int)c->cfg->calibrate.min_corners, corners, why, why_len) == 0;
}

/* The picture the page shows: @p rgb with @p corners (NULL: none) drawn, as DIR/live.png,
 * replaced whole (image_write_png writes atomically). */
static void write_picture(struct capture *c, const uint8_t *rgb, uint32_t width, uint32_t height,
                          const struct calcv_corners *corners)
{
    uint8_t *pic = NULL;
    int w, h;
    char path[HAL_MAX_PATH + 16];
    snprintf(path, sizeof(path), "%s/live.png", c->dir);
    if (calcv_preview(&c->board, rgb, (int)width, (int)height, corners, &pic, &w, &h) != 0)
        return;
    image_write_png(&c->hal->storage, path, pic, (uint32_t)w, (uint32_t)h, 3);
    free(pic);
}

/* The outline of @p k's corners, in parts of the image's width and height: the four corners
 * farthest along the diagonals (a whole board's own corners), for the page's coverage picture. */
static void say_outline(const struct calcv_corners *k, uint32_t width, uint32_t height)
{
    static const double dir[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    printf(",\"outline\":[");
    for (int d = 0; d < 4; d++) {
        int best = 0;
        for (int i = 1; i < k->count; i++)
            if (dir[d][0] * k->image[i][0] + dir[d][1] * k->image[i][1] >
                dir[d][0] * k->image[best][0] + dir[d][1] * k->image[best][1])
                best = i;
        printf("%s%.4f,%.4f", d ? "," : "", k->image[best][0] / width, k->image[best][1] / height);
    }
    putchar(']');
}

/* While the person places the board (json only): a picture about once a second, its corners
 * drawn as found, and whether the board is seen (or why not). */
static void live_picture(void *ctx)
{
    struct capture *c = ctx;
    if (!c->live || job_wall_ms() < c->live_next_ms)
        return;
    const uint8_t *rgb;
    int rc = scan_snapshot(scan_job_views(), c->hal, &c->params, c->guess, &rgb);
    if (rc != 0) { /* said by the layer that met it; the steps go on without pictures */
        c->live = 0;
        return;
    }
    static struct calcv_corners corners;
    char why[256] = "";
    uint32_t w = c->guess->cam_width, h = c->guess->cam_height;
    int found = find_board(c, rgb, w, h, &corners, why, sizeof(why));
    write_picture(c, rgb, w, h, &corners);
    printf("{\"event\":\"calib_live\",\"found\":%s,\"corners\":%d,\"why\":",
           found ? "true" : "false", corners.count);
    job_json_string(stdout, why);
    if (corners.count > 0)
        say_outline(&corners, w, h);
    printf("}\n");
    fflush(stdout);
    c->live_next_ms = job_wall_ms() + 1000.0;
}

/* Ask the person to put the target there (step @p step of @p steps; @p kind "board", "sphere"
 * or "compute"); the simulator's person does it at once, or (sim person = asked) does it and
 * waits to be told to go on, as a person would. @param may_go_back  the person may take the step
 * before again @retval 0 go on @retval 1 back to the step before @retval -EINTR stop */
static int place(struct capture *c, const struct board_target *t, const char *what, uint32_t step,
                 uint32_t steps, const char *kind, int may_go_back)
{
    char err[256];
    int rc = t != NULL ? board_place_target(c->hal, t, err, sizeof(err)) : -ENOSYS;
    int asked = rc == -ENOSYS || strcmp(c->cfg->sim.person, "asked") == 0;
    if (c->json) {
        printf("{\"event\":\"calib_place\",\"step\":%u,\"steps\":%u,\"kind\":\"%s\",\"detail\":",
               (unsigned)step, (unsigned)steps, kind);
        job_json_string(stdout, what);
        printf(",\"answers\":[%s]}\n", !asked        ? ""
                                       : may_go_back ? "\"continue\",\"back\""
                                                     : "\"continue\"");
    } else {
        printf("\n>>> %s\n", what);
    }
    fflush(stdout);
    if (rc != 0 && rc != -ENOSYS) {
        c->hal->log(HAL_LOG_ERROR, "%s", err);
        return rc;
    }
    if (rc == 0 && !asked) {
        if (!c->json)
            printf("    (the simulated person has done it)\n");
        return 0;
    }
    c->person = 1;
    if (!c->json) {
        printf("    Press Enter when it is done%s (Ctrl-D stops; the captures so far are kept).\n",
               may_go_back ? ", or type back and Enter to take the step before again" : "");
        fflush(stdout);
    }
    c->live = c->json && t != NULL && t->kind == BOARD_TARGET_BOARD;
    c->live_next_ms = 0.0;
    unsigned which;
    rc = answer_wait(c->hal, answers_place, may_go_back ? 2 : 1,
                     may_go_back ? "Enter (or 'continue') when it is done, 'back' for the step "
                                   "before"
                                 : "Enter (or 'continue') when it is done",
                     live_picture, c, &which);
    c->live = 0;
    return rc != 0 ? rc : (int)which;
}

/* After a capture whose board was not found, a person may put it right and take it again.
 * @retval 1 again @retval 0 go on @retval -EINTR stop */
static int ask_again(struct capture *c, const char *why)
{
    if (!c->person || c->board_found)
        return 0;
    if (c->json) {
        printf("{\"event\":\"calib_retry\",\"view\":%u,\"detail\":", (unsigned)c->view);
        job_json_string(stdout, why);
        printf(",\"answers\":[\"again\",\"skip\"]}\n");
    } else {
        printf("    Put it right and press Enter to take this view again, or type s and Enter to "
               "go on without it.\n");
    }
    fflush(stdout);
    unsigned which;
    int rc = answer_wait(c->hal, answers_retry, 4,
                         "Enter (or 'again') to take it again, 's' "
                         "(or 'skip') to go on without it",
                         NULL, NULL, &which);
    return rc != 0 ? rc : which == 0;
}

/* One capture: the table to @p angle_mdeg, the frames, target.ini and view.ini; then the board
 * looked for at once, so that the person hears now if it was not seen (@p why: why not). */
static int capture_one(struct capture *c, const struct calib_target_info *ti, char *why,
                       size_t why_len)
{
    struct hal *hal = c->hal;
    int rc = hal_table_move_to(&hal->turntable, ti->angle_mdeg);
    struct hal_turntable_status st;
    if (rc == 0)
        rc = hal_table_get_status(&hal->turntable, &st);
    if (rc != 0)
        return rc; /* the turntable client said why */
    if ((rc = scan_dir_begin_view(&hal->storage, c->dir, c->view)) != 0) {
        hal->log(HAL_LOG_ERROR, "cannot prepare %s/view_%03u: %s", c->dir, (unsigned)c->view,
                 strerror(-rc));
        return rc;
    }
    struct scan_frame_sink sink = {save_frame, c};
    struct scan_view view;
    struct scan_view_info info;
    rc = scan_take_view(scan_job_views(), hal, &c->params, c->guess, st.position_mdeg, &sink, &view,
                        &info);
    if (rc != 0)
        return rc;
    struct calib_target_info done = *ti;
    done.angle_mdeg = st.position_mdeg;
    if ((rc = calib_write_target(&hal->storage, c->dir, c->view, &done)) != 0)
        return rc;
    static struct scan_dir_view meta;
    scan_job_view_meta(c->cfg, &c->params, c->guess, c->view, &info, &meta);
    if ((rc = scan_dir_write_view(&hal->storage, c->dir, c->view, &meta)) != 0) {
        hal->log(HAL_LOG_ERROR, "cannot write %s/view_%03u/view.ini: %s", c->dir, (unsigned)c->view,
                 strerror(-rc));
        return rc;
    }
    static struct calcv_corners corners;
    corners.count = 0;
    why[0] = '\0';
    if (ti->kind == CALIB_TARGET_BOARD)
        c->board_found =
            find_board(c, view.white_rgb, view.width, view.height, &corners, why, why_len);
    if (c->json) {
        write_picture(c, view.white_rgb, view.width, view.height, &corners);
        printf("{\"event\":\"calib_capture\",\"view\":%u,\"placement\":%u,\"kind\":\"%s\","
               "\"angle_deg\":%.3f,\"tilt_deg\":%.1f,\"found\":%s,\"corners\":%d,\"points\":%u,"
               "\"why\":",
               (unsigned)c->view, (unsigned)ti->placement,
               ti->kind == CALIB_TARGET_BOARD ? "board" : "sphere", st.position_mdeg / 1000.0,
               ti->tilt_deg, ti->kind == CALIB_TARGET_BOARD && c->board_found ? "true" : "false",
               corners.count, (unsigned)info.valid_points);
        job_json_string(stdout, why);
        if (corners.count > 0)
            say_outline(&corners, view.width, view.height);
        printf("}\n");
    } else if (ti->kind != CALIB_TARGET_BOARD) {
        printf("    view_%03u at %7.2f deg: sphere, %u points\n", (unsigned)c->view,
               st.position_mdeg / 1000.0, (unsigned)info.valid_points);
    } else if (c->board_found) {
        printf("    view_%03u at %7.2f deg: board found, %d corners\n", (unsigned)c->view,
               st.position_mdeg / 1000.0, corners.count);
    } else {
        printf("    view_%03u at %7.2f deg: board NOT found: %s\n", (unsigned)c->view,
               st.position_mdeg / 1000.0, why);
    }
    fflush(stdout);
    return 0;
}

/* Step @p p's instruction (a board placement, or the sphere after the last) and target. */
static void step_target(const struct capture *c, uint32_t p, char *what, size_t len,
                        struct board_target *t)
{
    const struct calib_settings *s = &c->cfg->calibrate;
    if (p >= s->placement_count) {
        snprintf(what, len,
                 "Take the board off. Put the matte white sphere (%.0f mm) on "
                 "the table, %.0f mm from its centre towards the camera.",
                 s->sphere_diameter_mm, s->sphere_offset_mm);
        *t = (struct board_target){.kind = BOARD_TARGET_SPHERE,
                                   .diameter_mm = s->sphere_diameter_mm,
                                   .position_mm = {s->sphere_offset_mm, 0.0}};
        return;
    }
    double tilt = s->tilt_deg[p], off = s->offset_mm[p];
    char where[96];
    if (off == 0.0)
        snprintf(where, sizeof(where), "its centre on the table's centre");
    else
        snprintf(where, sizeof(where), "its centre %.0f mm to the %s of the table's centre",
                 fabs(off), off > 0.0 ? "right (as the camera sees it)" : "left");
    if (tilt >= 80.0)
        snprintf(what, len,
                 "Placement %u of %u: lay the board flat on the table, "
                 "%s, its top edge away from the camera.",
                 (unsigned)p + 1, (unsigned)s->placement_count, where);
    else
        snprintf(what, len,
                 "Placement %u of %u: stand the board on the table "
                 "facing the camera, %s, %s %.0f degrees.",
                 (unsigned)p + 1, (unsigned)s->placement_count, where,
                 tilt >= 0.0 ? "leaning back by" : "leaning forward by", fabs(tilt));
    *t = (struct board_target){.kind = BOARD_TARGET_BOARD,
                               .sheet = c->sheet,
                               .sheet_width = (uint32_t)c->sheet_w,
                               .sheet_height = (uint32_t)c->sheet_h,
                               .sheet_px_per_mm = CALIB_SHEET_PX_PER_MM,
                               .thickness_mm = s->board_thickness_mm,
                               .tilt_deg = tilt,
                               .position_mm = {0.0, off}};
}

/* The captures of step @p p: a board placement at each table angle (a view whose board was not
 * seen may be taken again), or the sphere all round. */
static int step_captures(struct capture *c, uint32_t p)
{
    const struct calib_settings *s = &c->cfg->calibrate;
    int sphere = p >= s->placement_count, rc = 0;
    uint32_t turns = sphere ? s->sphere_turns : s->turns;
    for (uint32_t k = 0; k < turns && rc == 0; k++) {
        struct calib_target_info ti = {.kind = sphere ? CALIB_TARGET_SPHERE : CALIB_TARGET_BOARD,
                                       .placement = p};
        if (sphere) {
            ti.angle_mdeg = (int32_t)lround(360000.0 * k / turns);
        } else {
            ti.tilt_deg = s->tilt_deg[p];
            ti.angle_mdeg =
                (int32_t)lround(((double)k - 0.5 * (turns - 1.0)) * s->turn_step_deg * 1000.0);
        }
        int again = 1;
        char why[256];
        while (rc == 0 && again == 1) { /* the same view again, at the same index */
            rc = capture_one(c, &ti, why, sizeof(why));
            again = rc == 0 && !sphere ? ask_again(c, why) : 0;
            rc = again < 0 ? again : rc;
        }
        c->view += rc == 0;
        c->kept = c->view > c->kept ? c->view : c->kept;
    }
    return rc;
}

/* Every step: the board's placements, then the sphere (when there are lights to place), and, for
 * a person, a last word before the computation. A person may go back a step (its captures are
 * taken again, over the old ones). */
static int run_steps(struct capture *c)
{
    const struct calib_settings *s = &c->cfg->calibrate;
    uint32_t steps = s->placement_count + (s->sphere_turns > 0 && c->cfg->light_count > 0);
    uint32_t first_view[CALIB_MAX_PLACEMENTS + 1];
    uint32_t p = 0;
    int rc = 0;
    while (rc == 0 && p <= steps) {
        if (p == steps && !c->person)
            break;
        char what[320];
        struct board_target t;
        if (p == steps) {
            rc = place(c, NULL, "Every capture is taken: go on to compute the calibration.", p,
                       steps, "compute", 1);
        } else {
            first_view[p] = c->view;
            step_target(c, p, what, sizeof(what), &t);
            rc = hal_table_move_to(&c->hal->turntable, 0); /* before the target is placed */
            if (rc == 0)
                rc = place(c, &t, what, p, steps, p < s->placement_count ? "board" : "sphere",
                           p > 0);
        }
        if (rc == 1) { /* back: the step before, from its first view */
            c->view = first_view[--p];
            rc = 0;
        } else if (rc == 0 && p < steps) {
            rc = step_captures(c, p++);
        } else if (rc == 0) {
            break;
        }
    }
    return rc;
}

int calibrate_capture(struct hal *hal, const struct app_config *cfg, const struct scan_calib *guess,
                      const char *dir, int json)
{
    struct capture c = {.hal = hal, .cfg = cfg, .guess = guess, .dir = dir, .json = json};
    calib_capture_params(cfg, &c.params);
    char err[HAL_MAX_PATH + 256];
    int lock_fd = -1;
    calib_board_from_settings(&cfg->calibrate, &c.board);
    int rc = calcv_board_image(&c.board, CALIB_SHEET_PX_PER_MM, &c.sheet, &c.sheet_w, &c.sheet_h);
    if (rc != 0) {
        hal->log(HAL_LOG_ERROR, "cannot draw the board: %s", strerror(-rc));
        return rc;
    }
    rc = scan_dir_open(&hal->storage, dir, SCAN_DIR_NEW, &lock_fd, err, sizeof(err));
    if (rc != 0) {
        hal->log(HAL_LOG_ERROR,
                 "%s (captures already there are computed with "
                 "'scanner calibrate --from %s')",
                 err, dir);
        goto out_sheet;
    }
    /* The config as it was, and the guess the captures were taken with (its sizes matter). */
    if ((rc = calib_write_file(&hal->storage, dir, SCAN_FILE_CONFIG, cfg->path)) != 0 ||
        (rc = calib_write_guess(&hal->storage, dir, guess)) != 0)
        goto out_dir;
    const unsigned spheres = cfg->light_count > 0 ? (unsigned)cfg->calibrate.sphere_turns : 0u;
    if (json) {
        printf("{\"event\":\"calib_start\",\"placements\":%u,\"turns\":%u,"
               "\"sphere_turns\":%u,\"dir\":",
               (unsigned)cfg->calibrate.placement_count, (unsigned)cfg->calibrate.turns, spheres);
        job_json_string(stdout, dir);
        printf("}\n");
    } else {
        printf("Calibration: %u board placements x %u table angles, then %u sphere angles. "
               "Every capture is kept in %s.\n",
               (unsigned)cfg->calibrate.placement_count, (unsigned)cfg->calibrate.turns, spheres,
               dir);
    }
    fflush(stdout);
    if ((rc = hal_table_home(&hal->turntable)) == 0)
        rc = run_steps(&c);
    if (rc == 0)
        rc = hal_table_move_to(&hal->turntable, 0);
    if (rc != 0)
        hal->log(HAL_LOG_WARN,
                 "calibration captures stopped (%s); the %u finished ones are "
                 "kept in %s: 'scanner calibrate --config %s --from %s --out FILE' computes from "
                 "them",
                 rc == -EINTR ? "stopped by request" : strerror(-rc), (unsigned)c.kept, dir,
                 cfg->path, dir);
out_dir:
    scan_dir_close(lock_fd);
out_sheet:
    free(c.sheet);
    return rc;
}

/* ---- the board to print ---- */

int calibrate_print_board(const struct hal_storage *st, const struct app_config *cfg,
                          const char *base)
{
    struct calcv_board b;
    uint8_t *grey = NULL;
    int w, h;
    const double dpi = 300.0;
    size_t len = strlen(base);
    if (len == 0 || base[len - 1] == '/') { /* else ".png" in the working directory */
        fprintf(stderr,
                "scanner: error: calibrate board --out '%s': give a file name without its "
                "ending (--out board writes board.png and board.svg)\n",
                base);
        return -EINVAL;
    }
    calib_board_from_settings(&cfg->calibrate, &b);
    int rc = calcv_board_image(&b, dpi / 25.4, &grey, &w, &h);
    if (rc != 0) {
        fprintf(stderr, "scanner: error: cannot draw the board: %s\n", strerror(-rc));
        return rc;
    }
    char path[HAL_MAX_PATH + 8];
    snprintf(path, sizeof(path), "%s.png", base);
    rc = image_write_png(st, path, grey, (uint32_t)w, (uint32_t)h, 1);
    /* whole pixels per square: the picture's true scale is its squares' */
    const double px_per_mm = lround(b.square_mm * dpi / 25.4) / b.square_mm;
    if (rc == 0) /* the SVG shows the picture at that scale: true size on any printer */
        rc = calib_write_svg(st, base, path, w, h, px_per_mm);
    free(grey);
    if (rc != 0) {
        fprintf(stderr, "scanner: error: cannot write %s: %s\n", path, strerror(-rc));
        return rc;
    }
    const double wmm = w / px_per_mm, hmm = h / px_per_mm;
    printf("%s.svg (true size, %.0f x %.0f mm) and %s.png (%dx%d, true size at %.2f dpi): a %s "
           "of %ux%u squares of %.1f mm. Print at 100%% (no fit-to-page), measure a square (and "
           "put what you measure in [calibrate] square_mm), and glue it flat on a rigid plate "
           "with the sheet's bottom edge on the plate's.\n",
           base, wmm, hmm, base, w, h, px_per_mm * 25.4, cfg->calibrate.board,
           (unsigned)b.squares_x, (unsigned)b.squares_y, b.square_mm);
    return 0;
}

/* ---- verification: a sphere of known diameter ---- */

int calibrate_verify(struct hal *hal, const struct app_config *cfg, const struct scan_calib *calib,
                     int json)
{
    const struct calib_settings *s = &cfg->calibrate;
    struct capture c = {.hal = hal, .cfg = cfg, .guess = calib, .json = json};
    struct board_target t = {.kind = BOARD_TARGET_SPHERE,
                             .diameter_mm = s->sphere_diameter_mm,
                             .position_mm = {s->sphere_offset_mm, 0.0}};
    char what[256];
    snprintf(what, sizeof(what),
             "Put the %.3f mm ball on the table, %.0f mm from its centre "
             "towards the camera.",
             s->sphere_diameter_mm, s->sphere_offset_mm);
    struct scan_params params = cfg->scan;
    params.colour.method = COLOUR_NONE;
    int rc = hal_table_home(&hal->turntable);
    if (rc == 0)
        rc = place(&c, &t, what, 0, 1, "sphere", 0);
    struct scan_view view;
    struct scan_view_info info;
    if (rc == 0)
        rc = scan_take_view(scan_job_views(), hal, &params, calib, 0, NULL, &view, &info);
    if (rc != 0)
        return rc;
    vec3 centre;
    uint32_t used;
    double radius = 0.5 * s->sphere_diameter_mm;
    double rms = calib_fit_sphere(view.range.xyz_mm, view.maps.reason,
                                  (size_t)view.width * view.height, 1, &radius, &centre, &used);
    if (rms < 0.0) {
        hal->log(HAL_LOG_ERROR,
                 "the ball was not seen (%u points): is it in view and lit by "
                 "the projector?",
                 (unsigned)used);
        return -ENODATA;
    }
    double cam_rms, proj_rms;
    calib_read_quality(cfg->calibration_file, &cam_rms, &proj_rms);
    const double found_mm = 2.0 * radius, error_mm = found_mm - s->sphere_diameter_mm;
    if (json) {
        printf("{\"event\":\"calib_verify\",\"points\":%u,\"diameter_mm\":%.4f,"
               "\"true_mm\":%.4f,\"error_mm\":%.4f,\"fit_rms_mm\":%.4f",
               (unsigned)used, found_mm, s->sphere_diameter_mm, error_mm, rms);
        if (cam_rms >= 0.0)
            printf(",\"camera_rms_px\":%.4f,\"projector_rms_px\":%.4f", cam_rms, proj_rms);
        printf("}\n");
        fflush(stdout);
        return 0;
    }
    printf("sphere: %u points, centre (%.2f, %.2f, %.2f) mm\n", (unsigned)used, centre.x, centre.y,
           centre.z);
    printf("diameter: %.3f mm measured, %.3f mm true: error %+.3f mm (%+.3f%%)\n", found_mm,
           s->sphere_diameter_mm, error_mm, 100.0 * error_mm / s->sphere_diameter_mm);
    printf("sphere fit RMS: %.4f mm\n", rms);
    if (cam_rms >= 0.0)
        printf("reprojection RMS (from the calibration): camera %.4f px, projector %.4f px\n",
               cam_rms, proj_rms);
    else
        printf("reprojection RMS: not recorded in %s (not written by scanner calibrate)\n",
               cfg->calibration_file);
    return 0;
}
