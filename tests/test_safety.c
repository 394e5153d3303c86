/* Faults and stops: bounded retries, clear errors, and lights and projector off on every path. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "job.h"
#include "test_util.h"

static struct test_rig t;

static int setup(void **state)
{
    (void)state;
    return test_rig_start_box(&t);
}

static int teardown(void **state)
{
    (void)state;
    test_rig_stop(&t);
    return 0;
}

static void test_transient_timeout_is_retried(void **state)
{
    (void)state;
    struct scan_view view;
    struct scan_view_info info;
    sim_ctl_inject_camera_fault(SIM_FAULT_TIMEOUT, 5, 2); /* two bad captures, retries = 2 */
    assert_int_equal(scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &view, &info),
                     0);
    assert_int_equal(info.capture_retries, 2);
    /* the 22 stripe patterns and the colour frames of config/sim.ini's method, each once */
    assert_int_equal(info.frames_captured, 22 + scan_light_frame_count(&t.cfg.scan, &t.calib));
    assert_true(scan_light_frame_count(&t.cfg.scan, &t.calib) > 0);
    assert_true(info.valid_points > 10000);
    assert_true(test_rig_dark());
}

/* A fault on every capture from frame @p at of a view on: the view stops with @p want_rc after
 * @p tries captures of that frame, projector and lights off. */
static void assert_view_stops(enum sim_cam_fault kind, uint64_t at, int want_rc, uint64_t tries)
{
    struct scan_view view;
    struct scan_view_info info;
    uint64_t start = sim_ctl_frames();
    sim_ctl_inject_camera_fault(kind, start + at, 100);
    assert_int_equal(scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &view, &info),
                     want_rc);
    assert_int_equal(sim_ctl_frames() - start, at + tries);
    assert_true(test_rig_dark());
    sim_ctl_inject_camera_fault(SIM_FAULT_NONE, 0, 0);
}

static void test_persistent_fault_stops_with_projector_off(void **state)
{
    (void)state;
    /* tried 1 + capture_retries times, then gave up and said which pattern */
    assert_view_stops(SIM_FAULT_CORRUPT, 7, -EIO, 1 + t.cfg.scan.capture_retries);
    assert_non_null(strstr(test_last_log, "giving up on pattern 7"));
}

static void test_unplugged_camera_not_retried(void **state)
{
    (void)state;
    assert_view_stops(SIM_FAULT_NO_DEVICE, 3, -ENODEV, 1); /* no retry can bring a camera back */
}

/* What a clean view at angle 0 gives: its colour, decoded columns and counts. */
static uint8_t clean_colour[HAL_MAX_PIXELS * 3];
static uint16_t clean_column[HAL_MAX_PIXELS];
static struct scan_view_info clean_info;
static struct scan_view view; /* the last view taken */

static void scan_clean_view(void)
{
    sim_ctl_inject_camera_fault(SIM_FAULT_NONE, 0, 0);
    assert_int_equal(
        scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &view, &clean_info), 0);
    size_t n = (size_t)t.cfg.scan.width * t.cfg.scan.height;
    memcpy(clean_colour, view.rgb, n * 3);
    memcpy(clean_column, view.maps.column, n * sizeof(clean_column[0]));
}

/* A view that had stale frames (exposed before the last change) is the clean view exactly. */
static void assert_view_is_clean(const struct scan_view_info *info)
{
    size_t n = (size_t)t.cfg.scan.width * t.cfg.scan.height;
    assert_int_equal(info->valid_points, clean_info.valid_points);
    assert_int_equal(info->frames_captured, clean_info.frames_captured);
    assert_memory_equal(view.rgb, clean_colour, n * 3);
    assert_memory_equal(view.maps.column, clean_column, n * sizeof(clean_column[0]));
}

/* The camera hands over frames it exposed before the pattern or the lights changed: each is
 * recognised by its start time, discarded and taken again, and the view is as if none came. */
static void test_stale_frames_are_discarded(void **state)
{
    (void)state;
    struct scan_view view;
    struct scan_view_info info;
    scan_clean_view();
    /* two in a row on a Gray-code pattern (within capture_retries = 2) */
    uint64_t start = sim_ctl_frames();
    sim_ctl_inject_camera_fault(SIM_FAULT_STALE, start + 6, 2);
    assert_int_equal(scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &view, &info),
                     0);
    assert_int_equal(info.capture_retries, 2);
    assert_non_null(strstr(test_last_log, "before the change had settled"));
    assert_view_is_clean(&info);
    /* the last colour frame, after its light changed */
    start = sim_ctl_frames();
    sim_ctl_inject_camera_fault(SIM_FAULT_STALE, start + clean_info.frames_captured - 1, 1);
    assert_int_equal(scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &view, &info),
                     0);
    assert_int_equal(info.capture_retries, 1);
    assert_view_is_clean(&info);
    assert_true(test_rig_dark());
    sim_ctl_inject_camera_fault(SIM_FAULT_NONE, 0, 0);
}

/* The simulated camera's timing is the V4L2 backend's: a capture asked for during a frame lets
 * that frame go by (it was being exposed when the pattern changed) as the one of drop_frames = 1
 * and takes the next, which begins at the next frame start; with drop_frames = 0 it is handed
 * the frame in flight, stamped with its start, which the scan tells from a fresh one and takes
 * again: every capture one stale frame, at the same rig time, and the view the clean one. */
static void test_camera_drops_the_frame_in_flight(void **state)
{
    (void)state;
    const double period = 1e6 / t.cfg.sim.frame_rate_hz;
    uint64_t now, asked;
    assert_true(t.cfg.sim.frame_rate_hz > 0.0 && t.cfg.camera.drop_frames == 1);
    assert_int_equal(hal_clock_now_us(&t.hal.clock, &now), 0);
    /* 10 ms into a frame */
    double next = ceil((double)now / period) * period;
    assert_int_equal(hal_clock_sleep_us(&t.hal.clock, (uint64_t)(next + 10000.0) - now), 0);
    assert_int_equal(hal_clock_now_us(&t.hal.clock, &asked), 0);
    struct hal_image img = {.rgb = t.scan->phase.taking.frame_rgb,
                            .capacity = sizeof(t.scan->phase.taking.frame_rgb)};
    assert_int_equal(hal_cam_capture(&t.hal.camera, &img), 0);
    assert_int_equal(hal_clock_now_us(&t.hal.clock, &now), 0);
    double frame_start = (double)asked - 10000.0 + period; /* the next start after asking */
    assert_true(fabs((double)img.start_us - frame_start) <= 1.0);
    assert_true(fabs((double)now - (frame_start + period + t.cfg.sim.readout_us)) <= 1.0);

    scan_clean_view();
    assert_int_equal(hal_clock_now_us(&t.hal.clock, &asked), 0);
    struct scan_view_info info;
    assert_int_equal(scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &view, &info),
                     0);
    uint64_t one_drop_us;
    assert_int_equal(hal_clock_now_us(&t.hal.clock, &now), 0);
    one_drop_us = now - asked;
    assert_int_equal(info.capture_retries, 0);
    struct hal_camera_config none = t.cfg.camera;
    none.drop_frames = 0;
    assert_int_equal(hal_cam_close(&t.hal.camera), 0);
    assert_int_equal(hal_cam_open(&t.hal.camera, &none), 0);
    asked = now;
    assert_int_equal(scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &view, &info),
                     0);
    assert_int_equal(hal_clock_now_us(&t.hal.clock, &now), 0);
    print_message("a view on the rig's clock: %.3f s dropping one frame, %.3f s handed the frames "
                  "in flight (%u of them discarded)\n",
                  one_drop_us / 1e6, (now - asked) / 1e6, (unsigned)info.capture_retries);
    assert_int_equal(info.capture_retries, info.frames_captured);
    assert_true(fabs((double)(now - asked) - (double)one_drop_us) <= 2.0 * period);
    assert_view_is_clean(&info);
    assert_int_equal(hal_cam_close(&t.hal.camera), 0);
    assert_int_equal(hal_cam_open(&t.hal.camera, &t.cfg.camera), 0);
}

/* A camera that only ever gives old frames: bounded retries, a message that says what to
 * change, the rig dark, and nothing decoded from the old pattern. */
static void test_persistent_stale_frames_stop_the_view(void **state)
{
    (void)state;
    assert_view_stops(SIM_FAULT_STALE, 9, -EIO, 1 + t.cfg.scan.capture_retries);
    assert_non_null(strstr(test_last_log, "giving up on pattern 9: every frame began before"));
    assert_non_null(strstr(test_last_log, "drop_frames"));
}

static int stop_after_frames(void)
{
    return sim_ctl_frames() >= 10;
}

static void test_stop_request_leaves_rig_dark(void **state)
{
    (void)state;
    struct scan_view view;
    struct scan_view_info info;
    t.hal.stop_requested = stop_after_frames;
    int rc = scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, NULL, &view, &info);
    t.hal.stop_requested = NULL;
    assert_int_equal(rc, -EINTR);
    assert_true(info.frames_captured < 22);
    assert_true(test_rig_dark());
}

/* The exposure check's frames ([scan] auto_exposure): a white and a black at the exposure asked,
 * measured as the decoder reads them, the camera back at its own and the rig dark after; a
 * 25th of the exposure makes the box mostly too dark (white minus black scales with it); a
 * fault on its second frame stops it after the retries, projector off. */
static void test_probe_contrast(void **state)
{
    (void)state;
    struct scan_contrast at_own, at_short;
    uint64_t start = sim_ctl_frames();
    const uint32_t own_us = t.cfg.scan.colour.exposure_us;
    assert_int_equal(scan_probe_contrast(t.scan, &t.hal, &t.cfg.scan, &t.calib, own_us, &at_own),
                     0);
    assert_int_equal(sim_ctl_frames() - start, 2);
    assert_true(test_rig_dark());
    assert_true(at_own.lit > 10000 && at_own.dark < at_own.lit / 10);
    assert_int_equal(
        scan_probe_contrast(t.scan, &t.hal, &t.cfg.scan, &t.calib, own_us / 25, &at_short), 0);
    assert_true(test_rig_dark());
    assert_true(at_short.dark > at_short.lit - at_short.dark && at_short.dark > 1000);
    assert_true(at_short.dark_median_dn > t.cfg.scan.shadow_contrast_dn &&
                at_short.dark_median_dn < t.cfg.scan.min_contrast_dn);
    /* the camera at its own exposure again: the same frames give the same measure */
    struct scan_contrast again;
    assert_int_equal(scan_probe_contrast(t.scan, &t.hal, &t.cfg.scan, &t.calib, own_us, &again), 0);
    assert_memory_equal(&again, &at_own, sizeof(again));
    start = sim_ctl_frames();
    sim_ctl_inject_camera_fault(SIM_FAULT_CORRUPT, start + 1, 100);
    assert_int_equal(scan_probe_contrast(t.scan, &t.hal, &t.cfg.scan, &t.calib, own_us, &again),
                     -EIO);
    sim_ctl_inject_camera_fault(SIM_FAULT_NONE, 0, 0);
    assert_int_equal(sim_ctl_frames() - start, 2 + t.cfg.scan.capture_retries);
    assert_true(test_rig_dark());
}

static uint64_t stop_at_frame;
static int stop_at(void)
{
    return sim_ctl_frames() >= stop_at_frame;
}

/* The lights' exposure check ([scan] auto_exposure, [colour] light_exposure_us): a dark frame
 * and each light alone at the camera's exposure, the rig dark after; at half the exposure the
 * brightest light's lift over the dark frame halves; a fault on a light's frame stops it after
 * the retries, and a stop request before a frame, lights off both times. */
static void test_probe_lights(void **state)
{
    (void)state;
    struct scan_light_probe at_own, at_half, again;
    const uint32_t own_us = t.cfg.scan.colour.exposure_us, lights = t.calib.light_count;
    assert_true(lights >= 2);
    uint64_t start = sim_ctl_frames();
    assert_int_equal(scan_probe_lights(t.scan, &t.hal, &t.cfg.scan, &t.calib, &at_own), 0);
    assert_int_equal(sim_ctl_frames() - start, 1 + lights);
    assert_true(test_rig_dark());
    assert_true(at_own.lit > 10000 && at_own.light < lights);
    assert_true(at_own.level_dn > at_own.dark_dn + 20 && at_own.level_dn < DECODE_SATURATED);
    assert_int_equal(hal_cam_set_exposure(&t.hal.camera, own_us / 2, t.cfg.scan.colour.gain_milli),
                     0);
    assert_int_equal(scan_probe_lights(t.scan, &t.hal, &t.cfg.scan, &t.calib, &at_half), 0);
    assert_int_equal(hal_cam_set_exposure(&t.hal.camera, own_us, t.cfg.scan.colour.gain_milli), 0);
    double lift = (double)at_own.level_dn - at_own.dark_dn;
    double lift_half = (double)at_half.level_dn - at_half.dark_dn;
    assert_true(fabs(lift_half - lift / 2) < 0.1 * lift);
    /* the same frames give the same measure */
    assert_int_equal(scan_probe_lights(t.scan, &t.hal, &t.cfg.scan, &t.calib, &again), 0);
    assert_memory_equal(&again, &at_own, sizeof(again));
    start = sim_ctl_frames();
    sim_ctl_inject_camera_fault(SIM_FAULT_CORRUPT, start + 2, 100); /* the second light's */
    assert_int_equal(scan_probe_lights(t.scan, &t.hal, &t.cfg.scan, &t.calib, &again), -EIO);
    sim_ctl_inject_camera_fault(SIM_FAULT_NONE, 0, 0);
    assert_int_equal(sim_ctl_frames() - start, 2 + 1 + t.cfg.scan.capture_retries);
    assert_true(test_rig_dark());
    stop_at_frame = sim_ctl_frames() + 2; /* the first light is on when it is asked */
    t.hal.stop_requested = stop_at;
    assert_int_equal(scan_probe_lights(t.scan, &t.hal, &t.cfg.scan, &t.calib, &again), -EINTR);
    t.hal.stop_requested = NULL;
    assert_true(test_rig_dark());
}

/* The exposure the lights call for (job_light_exposure_us): the brightest light's 95th
 * percentile brought to 95% of saturation, in whole milliseconds down, at most a frame at 30 fps,
 * never shorter than the camera's; the camera's own where the probe saw too little. */
static void test_light_exposure_choice(void **state)
{
    (void)state;
    struct scan_light_probe p = {.lit = 100000, .level_dn = 145, .dark_dn = 52};
    /* 10 ms x (237.5 - 52) / (145 - 52) = 19.9 ms */
    assert_int_equal(job_light_exposure_us(10000, &p, 250), 19000);
    p.level_dn = 60; /* dim lights: a frame at 30 fps at most */
    assert_int_equal(job_light_exposure_us(10000, &p, 250), JOB_LIGHT_MAX_US);
    assert_int_equal(job_light_exposure_us(40000, &p, 250), 40000); /* never shorter */
    p.level_dn = 238; /* already near saturation, or saturated */
    assert_int_equal(job_light_exposure_us(10000, &p, 250), 10000);
    p.level_dn = DECODE_SATURATED;
    assert_int_equal(job_light_exposure_us(10000, &p, 250), 10000);
    p = (struct scan_light_probe){.lit = JOB_DARK_PIXELS - 1, .level_dn = 100, .dark_dn = 52};
    assert_int_equal(job_light_exposure_us(10000, &p, 250), 10000); /* too little lit */
    p = (struct scan_light_probe){.lit = 100000, .level_dn = 52, .dark_dn = 52};
    assert_int_equal(job_light_exposure_us(10000, &p, 250), 10000); /* no lift at all */
    p = (struct scan_light_probe){.lit = 100000, .level_dn = 200, .dark_dn = 100};
    assert_int_equal(job_light_exposure_us(10000, &p, 250), 13000); /* a lower saturation */
    assert_int_equal(job_light_exposure_us(10000, &p, 200), 10000);
}

/* Lights on and projector on, then the one shutdown path: everything off. */
static void test_safe_state_turns_everything_off(void **state)
{
    (void)state;
    assert_int_equal(hal_gpio_set(&t.hal.gpio, HAL_GPIO_PROJECTOR_ENABLE, 1), 0);
    assert_int_equal(hal_gpio_set(&t.hal.gpio, HAL_GPIO_LIGHT_0 + 2, 1), 0);
    assert_int_equal(sim_ctl_line(HAL_GPIO_LIGHT_0 + 2), 1);
    assert_int_equal(hal_safe_state(&t.hal), 0);
    assert_true(test_rig_dark());
}

/* The projector follows its stored sequence: triggers step, reset returns to pattern 0. */
static void test_projector_sequence(void **state)
{
    (void)state;
    assert_int_equal(hal_gpio_pulse(&t.hal.gpio, &t.hal.clock, HAL_GPIO_PROJECTOR_RESET, 10), 0);
    assert_int_equal(sim_ctl_pattern_index(), 0);
    uint64_t t0 = sim_ctl_time_us();
    for (int i = 0; i < 5; i++)
        assert_int_equal(hal_gpio_pulse(&t.hal.gpio, &t.hal.clock, HAL_GPIO_PROJECTOR_TRIGGER, 10),
                         0);
    assert_int_equal(sim_ctl_pattern_index(), 5);
    assert_int_equal(sim_ctl_time_us() - t0, 50); /* virtual time: only sleeps move it */
    assert_int_equal(hal_gpio_pulse(&t.hal.gpio, &t.hal.clock, HAL_GPIO_PROJECTOR_RESET, 10), 0);
    assert_int_equal(sim_ctl_pattern_index(), 0);
}

/* Zephyr-style wrappers: a device without an op answers -ENOSYS, it does not crash. */
static void test_missing_ops_answer_enosys(void **state)
{
    (void)state;
    struct hal_turntable none = {NULL, NULL};
    struct hal_turntable_status st;
    assert_int_equal(hal_table_home(&none), -ENOSYS);
    assert_int_equal(hal_table_clear_alarm(&none), -ENOSYS);
    assert_int_equal(hal_table_move_to(&none, 1000), -ENOSYS);
    assert_int_equal(hal_table_get_status(&none, &st), -ENOSYS);
    static const struct hal_camera_ops partial = {0};
    struct hal_camera cam = {&partial, NULL};
    assert_int_equal(hal_cam_capture(&cam, NULL), -ENOSYS);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_transient_timeout_is_retried),
        cmocka_unit_test(test_persistent_fault_stops_with_projector_off),
        cmocka_unit_test(test_unplugged_camera_not_retried),
        cmocka_unit_test(test_stale_frames_are_discarded),
        cmocka_unit_test(test_persistent_stale_frames_stop_the_view),
        cmocka_unit_test(test_camera_drops_the_frame_in_flight),
        cmocka_unit_test(test_stop_request_leaves_rig_dark),
        cmocka_unit_test(test_safe_state_turns_everything_off),
        cmocka_unit_test(test_probe_contrast),
        cmocka_unit_test(test_probe_lights),
        cmocka_unit_test(test_light_exposure_choice),
        cmocka_unit_test(test_projector_sequence),
        cmocka_unit_test(test_missing_ops_answer_enosys),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
