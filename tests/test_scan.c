/* Whole turntable scans on the simulator (issue "full turntable scan", done-when): Modbus TCP and
 * RTU, the fused mesh against the true surface, offline re-processing, and ICP. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock_posix.h"
#include "mesh_compare.h"
#include "scan_dir.h"
#include "scan_job.h"
#include "storage_posix.h"
#include "test_util.h"

/* Scan @p object with 8 views over @p transport into @p dir and measure the mesh. */
static void scan_and_compare(const char *object, const char *transport, const char *dir,
                             struct mesh_comparison *r)
{
    static struct test_rig t;
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    snprintf(t.cfg.sim.object, sizeof(t.cfg.sim.object), "%s", object);
    snprintf(t.cfg.turntable.transport, sizeof(t.cfg.turntable.transport), "%s", transport);
    t.cfg.views = 8;
    assert_int_equal(test_rig_start(&t), 0);
    struct scan_job_opts opts = {.out_dir = dir, .replace = 1}; /* the last run's scan */
    int rc = scan_job_live(&t.hal, &t.cfg, &t.calib, &opts);
    test_rig_stop(&t);
    assert_int_equal(rc, 0);
    char mesh[256], truth[256], err[256];
    struct mesh_visibility vis;
    scan_dir_path(mesh, sizeof(mesh), dir, -1, "mesh.ply");
    scan_dir_path(truth, sizeof(truth), dir, -1, "truth_mesh.ply");
    assert_int_equal(mesh_visibility_from_scan(dir, &vis, err, sizeof(err)), 0);
    assert_int_equal(mesh_compare_files(mesh, truth, 100000, &vis, r, err, sizeof(err)), 0);
    print_message("%s over %s: result->truth mean %.3f mm; observable surface %.1f%%, within 1 mm "
                  "%.2f%%; symmetric mean %.3f mm (all of the truth: within 1 mm %.1f%%)\n",
                  object, transport, r->result_to_truth_mean_mm, 100.0 * r->observable_share,
                  100.0 * r->truth_observable_within_1mm, r->symmetric_observable_mean_mm,
                  100.0 * r->truth_within_1mm);
    /* targets: symmetric mean surface distance below 0.3 mm; 95% within 1 mm */
    assert_true(r->symmetric_observable_mean_mm < 0.3);
    assert_true(r->truth_observable_within_1mm >= 0.95);
    assert_true(r->observable_share > 0.7); /* the measure must not hide a blind rig */
}

static void test_bunny_over_tcp_and_process_reproduces(void **state)
{
    (void)state;
    struct mesh_comparison r;
    scan_and_compare("mesh", "tcp", "build/test_scan/bunny", &r);
    struct hal hal;
    memset(&hal, 0, sizeof(hal));
    hal.log = test_rig_log;
    storage_posix_init(&hal.storage);
    clock_posix_init(&hal.clock);
    struct scan_job_opts opts = {.out_dir = "build/test_scan/bunny_processed", .replace = 1};
    assert_int_equal(scan_job_process(&hal, "build/test_scan/bunny", &opts), 0);
    assert_true(test_files_equal("build/test_scan/bunny/mesh.ply",
                                 "build/test_scan/bunny_processed/mesh.ply"));
    assert_true(test_files_equal("build/test_scan/bunny/mesh.obj",
                                 "build/test_scan/bunny_processed/mesh.obj"));
    assert_true(test_files_equal("build/test_scan/bunny/view_005/cloud.ply",
                                 "build/test_scan/bunny_processed/view_005/cloud.ply"));
}

static void test_cylinder_over_rtu(void **state)
{
    (void)state;
    struct mesh_comparison r;
    scan_and_compare("cylinder", "rtu", "build/test_scan/cylinder", &r);
}

/* A view whose reported angle is 0.6 degrees off: ICP against the previous view finds it. */
static void test_icp_corrects_a_wrong_angle(void **state)
{
    (void)state;
    static struct test_rig t;
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    assert_int_equal(test_rig_start(&t), 0);
    struct scan_view view;
    struct scan_view_info info;
    struct icp_report rep;
    struct frame_xform pose, truth;
    icp_reset();
    assert_int_equal(scan_take_view(&t.hal, &t.cfg.scan, &t.calib, 0, NULL, &view, &info), 0);
    scan_view_pose(&t.calib, &view, &pose);
    assert_int_equal(scan_register_view(&t.cfg.registration, &t.calib, &view, &pose, &rep), 0);
    assert_false(rep.has_pair);
    assert_int_equal(hal_table_move_to(&t.hal.turntable, 30000), 0);
    assert_int_equal(scan_take_view(&t.hal, &t.cfg.scan, &t.calib, 30600, NULL, &view, &info), 0);
    frame_object_from_camera(&t.calib, 30000, &truth);
    scan_view_pose(&t.calib, &view, &pose); /* from the wrong angle, 30.6 degrees */
    assert_int_equal(scan_register_view(&t.cfg.registration, &t.calib, &view, &pose, &rep), 0);
    test_rig_stop(&t);
    /* compare where each pose puts a point on the object, 600 mm in front of the camera */
    vec3 p = v3(0, 0, 600);
    double before = 30600 - 30000, after_mm = v3_len(v3_sub(frame_point(&pose, p),
                                                             frame_point(&truth, p)));
    print_message("ICP: coupled %.1f%% -> %.1f%%, correction %.3f deg, remaining error %.3f mm "
                  "(0.6 deg was %.3f mm)\n",
                  100.0 * rep.coupled_before / rep.overlap_before,
                  100.0 * rep.coupled_after / rep.overlap_after, rep.correction_deg, after_mm,
                  before / 1000.0 * M_PI / 180.0 * 56.0);
    assert_true(rep.accepted);
    assert_true(rep.coupled_after > rep.coupled_before);
    assert_true(after_mm < 0.15); /* the 0.6 degree error put it ~0.6 mm off */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_icp_corrects_a_wrong_angle),
        cmocka_unit_test(test_bunny_over_tcp_and_process_reproduces),
        cmocka_unit_test(test_cylinder_over_rtu),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
