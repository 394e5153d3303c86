/* Shared helpers of the tests: a simulated rig from a config, and view quality against truth. */
#ifndef TEST_UTIL_H
#define TEST_UTIL_H

#include "board.h"
#include "config.h"
#include "scan.h"
#include "sim_ctl.h"

struct test_rig {
    struct app_config cfg;
    struct scan_calib calib;
    struct hal hal;
    struct scan_ctx *scan; /* the view buffers: the process's (scan_job_views) */
};

/** Every pattern frame of a view as the decoder saw it (grey; the white frame converted from
 *  RGB as the scan converts it): the decoder reads each frame and lets it go, so a test that
 *  compares it with decode_reference keeps them through this frame sink. */
struct test_frames {
    uint8_t *grey[DECODE_MAX_PATTERNS]; /* malloc'd, as they come */
    size_t pixels;
    uint32_t saturation_dn;
};
/** A sink (for scan_take_view) that fills @p f, which must start zeroed with @p pixels and
 *  @p saturation_dn set. */
struct scan_frame_sink test_frames_sink(struct test_frames *f);
/** Free what @p f holds. */
void test_frames_free(struct test_frames *f);

/** Last message logged through the test logger, and how many errors were logged. */
extern char test_last_log[512];
extern int test_error_count;

/** @retval 1 when both files exist and hold the same bytes */
int test_files_equal(const char *a, const char *b);
/** @retval how many temporary files of an atomic write (NAME.tmp.XXXXXX) are in @p dir */
int test_temporaries_in(const char *dir);
/** @retval 1 when the simulated projector and every light are off */
int test_rig_dark(void);

/** Forget the warnings and errors logged so far (test_error_count starts again at 0). */
void test_log_clear(void);
/** @retval 1 when exactly one error was logged since test_log_clear() and it contains
 *  @p needle (one fault, one error line, naming its cause); 0 after printing what was logged */
int test_log_one_error(const char *needle);
/** @retval 1 when a warning or error since test_log_clear() contains @p needle; 0 after
 *  printing what was logged instead */
int test_log_has(const char *needle);

/** The quiet logger the test rig uses (records the last message, and warnings and errors). */
void test_rig_log(enum hal_log_level level, const char *fmt, ...);

/** Load a config and its calibration. @retval 0 ok (fails the test otherwise) */
int test_rig_load(struct test_rig *t, const char *config_path);
/** board_init + scan_open with the quiet test logger. @retval 0 or the error */
int test_rig_start(struct test_rig *t);
/** config/sim.ini's rig with a coarse box for its object (quick to render; the geometry does
 *  not matter to the test), loaded and started. @retval 0 or the error */
int test_rig_start_box(struct test_rig *t);
/** scan_close + board_shutdown. */
void test_rig_stop(struct test_rig *t);

/** scan_save_cloud of @p view with its turntable pose. @retval what it returned */
int scan_save_cloud_at_turntable_pose(struct test_rig *t, const struct scan_view *view,
                                      const char *path);

/** How well the last view matches the simulator's ground truth. */
struct view_quality {
    uint32_t lit;         /**< pixels where the projector lights the visible surface */
    uint32_t lit_correct; /**< of those: valid and column within +-1 of the truth */
    uint32_t lit_valid;   /**< of lit: valid, right or not */
    uint32_t lit_off;     /**< of lit: valid but more than +-1 column off */
    uint32_t lit_wrong;   /**< of those: off every lit column of its 3x3 footprint */
    uint32_t lit_head_on; /**< lit pixels not on the very dark paint, incidence below 75 deg */
    uint32_t lit_head_on_correct;
    uint32_t lit_head_on_valid; /**< of lit_head_on: valid, right or not */
    uint32_t lit_head_on_off;   /**< of lit_head_on: valid but more than +-1 column off */
    uint32_t lit_head_on_wrong; /**< of those: off every lit pixel's column in the 3x3 around it
                                     (not a blurred pixel seeing its neighbour's surface) */
    uint32_t head_on_reason[SCAN_REASON_COUNT]; /**< lit_head_on pixels by reason */
    double stripe_px;           /**< finest projected stripe (2 columns) in camera pixels, median */
    uint32_t valid;             /**< all valid pixels */
    uint32_t valid_unlit;       /**< valid pixels the projector does not light (must be 0) */
    uint32_t dark;              /**< lit pixels on the very dark paint */
    uint32_t dark_flagged;      /**< of those: rejected */
    uint32_t dark_correct;      /**< of those: valid and within +-1 column of the truth */
    uint32_t saturated;         /**< lit pixels whose white frame (the view's colour) saturates */
    uint32_t saturated_correct; /**< of those: valid and within +-1 column of the truth */
    uint32_t outliers_2mm;      /**< valid points farther than 2 mm from the true surface */
    double normal_err_deg;      /**< mean angle between estimated and true normals, valid pixels */
    double depth_rms_mm;        /**< RMS of reconstructed minus true depth (z), valid pixels */
    double max_surface_mm;      /**< largest point-to-true-tangent-plane distance */
    double distance_mm;         /**< mean camera-to-surface distance over lit pixels */
};

/** Incidence limit of lit_head_on: beyond 75 degrees the projector's light is a few grey levels. */
#define TEST_MAX_INCIDENCE_DEG 75.0

/** Compare @p view with the rig's truth. */
void test_measure_view(const struct sim_rig *rig, const struct scan_view *view,
                       struct view_quality *q);

#endif
