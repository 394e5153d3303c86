/* Whole scans that fail midway (the table stalls, the camera goes away): a clear error naming
 * the view and what the controller did, every finished view kept, no view at a wrong angle, and
 * `resume` finishing the scan with the model an uninterrupted scan gives. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "scan_dir.h"
#include "scan_job.h"
#include "test_util.h"
#include "tt_server.h"

#define VIEWS 4u /* at 0, 90, 180 and 270 degrees */
#define OUT "build/test_scan_faults"

static struct test_rig t;

/* The rig of config/sim.ini with a box (quick to render) and four views, in a file: a scan
 * keeps its config, and resume and process read it back from there. */
static int setup(void **state)
{
    (void)state;
    if (system("rm -rf " OUT " && mkdir -p " OUT " && sed -e 's/^views = .*/views = 4/' "
               "-e 's/^object = .*/object = box/' "
               "-e \"s|^calibration = .*|calibration = $PWD/config/sim-calib.ini|\" "
               "config/sim.ini > " OUT "/rig.ini && echo 'segments = 16' >> " OUT "/rig.ini") != 0)
        return -1;
    if (test_rig_load(&t, OUT "/rig.ini") != 0 || t.cfg.views != VIEWS)
        return -1;
    return test_rig_start(&t);
}

static int teardown(void **state)
{
    (void)state;
    test_rig_stop(&t);
    return 0;
}

static int scan(const char *dir)
{
    struct scan_job_opts opts = {.out_dir = dir, .replace = 1}; /* the last run's scan */
    return scan_job_live(&t.hal, &t.cfg, &t.calib, &opts);
}

/* As 'scanner resume' does: the scan's own settings (its config.ini holds what it chose). */
static int resume(const char *dir, int clear_alarm)
{
    struct scan_job_opts opts = {.clear_alarm = clear_alarm};
    static struct app_config cfg;
    static struct scan_calib calib;
    char err[512];
    int rc = scan_job_load_settings(dir, NULL, 1, &cfg, &calib, err, sizeof(err));
    if (rc != 0)
        return rc;
    rc = scan_job_resume(&t.hal, &cfg, &calib, dir, &opts);
    return rc != 0 ? rc : scan_job_process(&t.hal, dir, &opts);
}

/* Views 0 .. done-1 complete and at their angles, the others not started. */
static void assert_views(const char *dir, uint32_t done)
{
    char path[256];
    struct stat st;
    for (uint32_t v = 0; v < VIEWS; v++) {
        static struct scan_dir_view meta;
        char err[512];
        scan_dir_path(path, sizeof(path), dir, (int)v, "view.ini");
        if (v < done) {
            assert_int_equal(scan_dir_read_view(dir, v, &meta, err, sizeof(err)), 0);
            assert_true(labs((long)meta.angle_mdeg - (long)(v * 90000u)) <=
                        (long)t.cfg.turntable.tolerance_mdeg);
        } else {
            assert_int_not_equal(stat(path, &st), 0);
        }
    }
}

static void set_stall(int32_t at_mdeg)
{
    struct tt_server *server = sim_ctl_turntable();
    pthread_mutex_lock(&server->lock);
    server->ctrl.stall_at_mdeg = at_mdeg;
    pthread_mutex_unlock(&server->lock);
}

/* The model of the scan in @p dir is the reference's, to the byte. */
static void assert_model_is_the_reference(const char *dir)
{
    char path[256], ref[256];
    scan_dir_path(path, sizeof(path), dir, -1, "mesh.ply");
    scan_dir_path(ref, sizeof(ref), OUT "/reference", -1, "mesh.ply");
    assert_true(test_files_equal(path, ref));
}

/* The reference: the same scan, nothing going wrong. */
static uint64_t reference_frames; /* captures it took, all views */

static void test_reference_scan(void **state)
{
    (void)state;
    uint64_t start = sim_ctl_frames();
    assert_int_equal(scan(OUT "/reference"), 0);
    reference_frames = sim_ctl_frames() - start;
    assert_views(OUT "/reference", VIEWS);
}

/* The table jams on its way to view 2: the scan stops there and says where the table is and
 * which alarm it raised; views 0 and 1 stay; a resume without clearing the alarm is refused
 * and loses nothing; with --clear-alarm it finishes, and the model is the reference's. */
static void test_stall_stops_scan_then_resume_finishes_it(void **state)
{
    (void)state;
    const char *dir = OUT "/stall";
    char path[256], ref[256];
    assert_int_equal(hal_table_home(&t.hal.turntable), 0); /* so that homing passes no stall */
    set_stall(135000); /* between view 1 (90 deg) and view 2 (180 deg) */
    test_log_clear();
    assert_int_equal(scan(dir), -EIO);
    /* one fault, one error, said by the layer that met it; then what is kept and how to go on */
    assert_true(test_log_one_error(
        "turntable: move to 180.000 deg: the controller raised alarm 1 (stall (following error)) "
        "at 135.000 deg"));
    assert_true(test_log_has("view 2 was not taken at 180.000 deg: the table stopped at "
                             "135.000 deg with alarm 1; once it turns freely, the 2 "
                             "finished views are kept in build/test_scan_faults/stall: 'scanner "
                             "resume build/test_scan_faults/stall --clear-alarm' takes the rest"));
    assert_views(dir, 2);
    assert_true(test_rig_dark());
    set_stall(INT32_MIN); /* the operator frees the table */

    test_log_clear();
    assert_int_not_equal(resume(dir, 0), 0); /* the alarm still blocks motion */
    assert_true(test_log_has("the turntable did not home (if it reports an alarm: --clear-alarm)"));
    assert_views(dir, 2);

    assert_int_equal(resume(dir, 1), 0);
    assert_views(dir, VIEWS);
    assert_model_is_the_reference(dir);
    for (uint32_t v = 0; v < VIEWS; v++) { /* each view's frames too, e.g. the white one */
        assert_int_equal(scan_dir_find_frame(path, sizeof(path), dir, v, 0), 0);
        assert_int_equal(scan_dir_find_frame(ref, sizeof(ref), OUT "/reference", v, 0), 0);
        assert_true(test_files_equal(path, ref));
    }
    assert_true(test_rig_dark());
}

/* The camera goes away in the middle of view 2: the error names the view and its angle, the
 * half-taken view is not kept as finished, and resume retakes it whole. */
static void test_camera_lost_mid_view_then_resume_finishes_it(void **state)
{
    (void)state;
    const char *dir = OUT "/camera";
    /* a scan begins with the exposure checks ([scan] auto_exposure): a white and a black, then
     * a dark frame and each light alone */
    const uint64_t check = 2 + 1 + t.calib.light_count;
    uint64_t per_view = (reference_frames - check) / VIEWS;
    assert_true(per_view > 10 && (reference_frames - check) % VIEWS == 0);
    uint64_t start = sim_ctl_frames();
    sim_ctl_inject_camera_fault(SIM_FAULT_NO_DEVICE, start + check + 2 * per_view + 7, 1000000);
    test_log_clear();
    assert_int_equal(scan(dir), -ENODEV);
    assert_true(test_log_one_error("camera: giving up on pattern 7: No such device"));
    assert_true(test_log_has("view 2 at 180.000 deg was not finished (No such device); the 2 "
                             "finished views "
                             "are kept in build/test_scan_faults/camera: 'scanner resume "
                             "build/test_scan_faults/camera' takes the rest"));
    assert_views(dir, 2);
    assert_true(test_rig_dark());
    sim_ctl_inject_camera_fault(SIM_FAULT_NONE, 0, 0); /* plugged back in */

    assert_int_equal(resume(dir, 0), 0);
    assert_views(dir, VIEWS);
    assert_model_is_the_reference(dir);
    assert_true(test_rig_dark());
}

static int stop_now(void)
{
    return 1;
}

/* Stopped before its first view, in the exposure check ([scan] auto_exposure): no frame taken,
 * the rig dark, and the settings kept (before the check they were kept first too), so that
 * resume takes every view and the model is the reference's. */
static void test_stop_in_the_exposure_check_then_resume(void **state)
{
    (void)state;
    const char *dir = OUT "/checked";
    uint64_t start = sim_ctl_frames();
    test_log_clear();
    t.hal.stop_requested = stop_now;
    int rc = scan(dir);
    t.hal.stop_requested = NULL;
    assert_int_equal(rc, -EINTR);
    assert_int_equal(sim_ctl_frames(), start);
    assert_true(test_rig_dark());
    assert_true(test_log_has("scan stopped by request before its first view: nothing taken; "
                             "'scanner resume build/test_scan_faults/checked' takes the views"));
    assert_views(dir, 0);
    assert_int_equal(resume(dir, 0), 0);
    assert_views(dir, VIEWS);
    assert_model_is_the_reference(dir);
    assert_true(test_rig_dark());
}

static uint64_t stop_frame;
static int stop_at_frame(void)
{
    return sim_ctl_frames() >= stop_frame;
}

/* A camera that cannot change its exposure (a V4L2 device without the control): the lights'
 * check finds it before the first view, says so once and takes the lights at the camera's own
 * exposure, keeping nothing it did not choose (before the check, every view would have failed
 * on its first light frame). Stopped in the first view: only the check matters here. */
static void test_camera_without_exposure_control(void **state)
{
    (void)state;
    const char *dir = OUT "/fixed-exposure";
    const struct hal_camera_ops *own = t.hal.camera.ops;
    static struct hal_camera_ops fixed;
    fixed = *own;
    fixed.set_exposure = NULL; /* hal_cam_set_exposure answers -ENOSYS */
    t.hal.camera.ops = &fixed;
    stop_frame = sim_ctl_frames() + 2 + 1 + t.calib.light_count + 3;
    t.hal.stop_requested = stop_at_frame;
    test_log_clear();
    int rc = scan(dir);
    t.hal.stop_requested = NULL;
    t.hal.camera.ops = own;
    assert_int_equal(rc, -EINTR);
    assert_true(test_rig_dark());
    assert_true(test_log_has("which cannot be taken (the camera: Function not implemented): the "
                             "exposure as set"));
    char path[256], text[8192];
    scan_dir_path(path, sizeof(path), dir, -1, "config.ini");
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    size_t n = fread(text, 1, sizeof(text) - 1, f);
    fclose(f);
    text[n] = '\0';
    assert_null(strstr(text, "light_exposure_us"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reference_scan),
        cmocka_unit_test(test_stall_stops_scan_then_resume_finishes_it),
        cmocka_unit_test(test_camera_lost_mid_view_then_resume_finishes_it),
        cmocka_unit_test(test_stop_in_the_exposure_check_then_resume),
        cmocka_unit_test(test_camera_without_exposure_control),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
