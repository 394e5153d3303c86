/* `scanner calibrate`: the procedure a person follows at the rig, its captures, the printable
 * board and the verification scan (the computation is app/calib_solve.c). */
#define _POSIX_C_SOURCE 200809L
#include "calibrate.h"

#include "board.h"
#include "calib_cv.h"
#include "calib_priv.h"
#include "config.h"
#include "decode.h"
#include "image_io.h"
#include "scan.h"
#include "scan_dir.h"
#include "scan_job.h"

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
    struct scan_params params;
    struct calcv_board board;
    uint8_t *sheet; /* the board as printed, for the simulated person */
    int sheet_w, sheet_h;
    int person;      /* 1: a person places the targets (a rig), and may take a view again */
    int board_found; /* the last board capture showed the board */
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

/* Ask the person to put the target there; the simulator's person does it at once. */
static int place(struct capture *c, const struct board_target *t, const char *what)
{
    char err[256];
    printf("\n>>> %s\n", what);
    fflush(stdout);
    int rc = board_place_target(c->hal, t, err, sizeof(err));
    if (rc == 0) {
        printf("    (the simulated person has done it)\n");
        return 0;
    }
    if (rc != -ENOSYS) {
        c->hal->log(HAL_LOG_ERROR, "%s", err);
        return rc;
    }
    c->person = 1;
    printf("    Press Enter when it is done (Ctrl-D stops; the captures so far are kept).\n");
    fflush(stdout);
    char line[64];
    if (fgets(line, sizeof(line), stdin) == NULL || c->hal->stop_requested())
        return -EINTR;
    return 0;
}

/* After a capture whose board was not found, a person may put it right and take it again.
 * @retval 1 again @retval 0 go on @retval -EINTR stop */
static int ask_again(struct capture *c)
{
    if (!c->person || c->board_found)
        return 0;
    printf("    Put it right and press Enter to take this view again, or type s and Enter to "
           "go on without it.\n");
    fflush(stdout);
    char line[64];
    if (fgets(line, sizeof(line), stdin) == NULL || c->hal->stop_requested())
        return -EINTR;
    return line[0] == 's' || line[0] == 'S' ? 0 : 1;
}

/* One capture: the table to @p angle_mdeg, the frames, target.ini and view.ini; then the board
 * looked for at once, so that the person hears now if it was not seen. */
static int capture_one(struct capture *c, const struct calib_target_info *ti)
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
    if (ti->kind == CALIB_TARGET_BOARD) {
        static struct calcv_corners corners;
        static uint8_t grey[HAL_MAX_PIXELS];
        char why[256];
        decode_rgb_to_grey(view.white_rgb, grey, (size_t)view.width * view.height, 256);
        c->board_found =
            calcv_find_corners(&c->board, grey, (int)view.width, (int)view.height,
                               (int)c->cfg->calibrate.min_corners, &corners, why, sizeof(why)) == 0;
        if (c->board_found)
            printf("    view_%03u at %7.2f deg: board found, %d corners\n", (unsigned)c->view,
                   st.position_mdeg / 1000.0, corners.count);
        else
            printf("    view_%03u at %7.2f deg: board NOT found: %s\n", (unsigned)c->view,
                   st.position_mdeg / 1000.0, why);
    } else {
        printf("    view_%03u at %7.2f deg: sphere, %u points\n", (unsigned)c->view,
               st.position_mdeg / 1000.0, (unsigned)info.valid_points);
    }
    fflush(stdout);
    return 0;
}

static int board_steps(struct capture *c)
{
    const struct calib_settings *s = &c->cfg->calibrate;
    int rc = 0;
    for (uint32_t p = 0; p < s->placement_count && rc == 0; p++) {
        double tilt = s->tilt_deg[p], off = s->offset_mm[p];
        char what[320], where[96];
        if (off == 0.0)
            snprintf(where, sizeof(where), "its centre on the table's centre");
        else
            snprintf(where, sizeof(where), "its centre %.0f mm to the %s of the table's centre",
                     fabs(off), off > 0.0 ? "right (as the camera sees it)" : "left");
        if (tilt >= 80.0)
            snprintf(what, sizeof(what),
                     "Placement %u of %u: lay the board flat on the table, "
                     "%s, its top edge away from the camera.",
                     (unsigned)p + 1, (unsigned)s->placement_count, where);
        else
            snprintf(what, sizeof(what),
                     "Placement %u of %u: stand the board on the table "
                     "facing the camera, %s, %s %.0f degrees.",
                     (unsigned)p + 1, (unsigned)s->placement_count, where,
                     tilt >= 0.0 ? "leaning back by" : "leaning forward by", fabs(tilt));
        struct board_target t = {.kind = BOARD_TARGET_BOARD,
                                 .sheet = c->sheet,
                                 .sheet_width = (uint32_t)c->sheet_w,
                                 .sheet_height = (uint32_t)c->sheet_h,
                                 .sheet_px_per_mm = CALIB_SHEET_PX_PER_MM,
                                 .thickness_mm = s->board_thickness_mm,
                                 .tilt_deg = tilt,
                                 .position_mm = {0.0, off}};
        /* the table turns to the first angle before the person places the board */
        rc = hal_table_move_to(&c->hal->turntable, 0);
        if (rc == 0)
            rc = place(c, &t, what);
        for (uint32_t k = 0; k < s->turns && rc == 0; k++) {
            struct calib_target_info ti = {
                .kind = CALIB_TARGET_BOARD,
                .placement = p,
                .tilt_deg = tilt,
                .angle_mdeg = (int32_t)lround(((double)k - 0.5 * (s->turns - 1.0)) *
                                              s->turn_step_deg * 1000.0)};
            int again = 1;
            while (rc == 0 && again == 1) /* the same view again, at the same index */
                if ((rc = capture_one(c, &ti)) == 0 && (again = ask_again(c)) < 0)
                    rc = again;
            c->view += rc == 0;
        }
    }
    return rc;
}

static int sphere_steps(struct capture *c)
{
    const struct calib_settings *s = &c->cfg->calibrate;
    if (s->sphere_turns == 0 || c->cfg->light_count == 0)
        return 0;
    char what[256];
    snprintf(what, sizeof(what),
             "Take the board off. Put the matte white sphere (%.0f mm) on "
             "the table, %.0f mm from its centre towards the camera.",
             s->sphere_diameter_mm, s->sphere_offset_mm);
    struct board_target t = {.kind = BOARD_TARGET_SPHERE,
                             .diameter_mm = s->sphere_diameter_mm,
                             .position_mm = {s->sphere_offset_mm, 0.0}};
    int rc = hal_table_move_to(&c->hal->turntable, 0);
    if (rc == 0)
        rc = place(c, &t, what);
    for (uint32_t k = 0; k < s->sphere_turns && rc == 0; k++) {
        struct calib_target_info ti = {.kind = CALIB_TARGET_SPHERE,
                                       .placement = s->placement_count,
                                       .angle_mdeg =
                                           (int32_t)lround(360000.0 * k / s->sphere_turns)};
        rc = capture_one(c, &ti);
        c->view += rc == 0;
    }
    return rc;
}

int calibrate_capture(struct hal *hal, const struct app_config *cfg, const struct scan_calib *guess,
                      const char *dir)
{
    struct capture c = {.hal = hal, .cfg = cfg, .guess = guess, .dir = dir};
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
    printf("Calibration: %u board placements x %u table angles, then %u sphere angles. Every "
           "capture is kept in %s.\n",
           (unsigned)cfg->calibrate.placement_count, (unsigned)cfg->calibrate.turns,
           cfg->light_count > 0 ? (unsigned)cfg->calibrate.sphere_turns : 0u, dir);
    if ((rc = hal_table_home(&hal->turntable)) == 0 && (rc = board_steps(&c)) == 0)
        rc = sphere_steps(&c);
    if (rc == 0)
        rc = hal_table_move_to(&hal->turntable, 0);
    if (rc != 0)
        hal->log(HAL_LOG_WARN,
                 "calibration captures stopped (%s); the %u finished ones are "
                 "kept in %s: 'scanner calibrate --config %s --from %s --out FILE' computes from "
                 "them",
                 rc == -EINTR ? "stopped by request" : strerror(-rc), (unsigned)c.view, dir,
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

int calibrate_verify(struct hal *hal, const struct app_config *cfg, const struct scan_calib *calib)
{
    const struct calib_settings *s = &cfg->calibrate;
    struct capture c = {.hal = hal, .cfg = cfg, .guess = calib};
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
        rc = place(&c, &t, what);
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
    printf("sphere: %u points, centre (%.2f, %.2f, %.2f) mm\n", (unsigned)used, centre.x, centre.y,
           centre.z);
    printf("diameter: %.3f mm measured, %.3f mm true: error %+.3f mm (%+.3f%%)\n", 2.0 * radius,
           s->sphere_diameter_mm, 2.0 * radius - s->sphere_diameter_mm,
           100.0 * (2.0 * radius - s->sphere_diameter_mm) / s->sphere_diameter_mm);
    printf("sphere fit RMS: %.4f mm\n", rms);
    if (cam_rms >= 0.0)
        printf("reprojection RMS (from the calibration): camera %.4f px, projector %.4f px\n",
               cam_rms, proj_rms);
    else
        printf("reprojection RMS: not recorded in %s (not written by scanner calibrate)\n",
               cfg->calibration_file);
    return 0;
}
